"""Each effect at a typical magnitude changes the output where STAND.md §5 says it shows,
and not where it should not; balances and analytic values where the physics gives them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec
from sim.config import StandConfig
from sim.effects import EffectSpec
from sim.model import Model, ModelRun, SimResult
from sim.params import StandParams
from tests.effects.helpers import (
    RATE,
    best_lag,
    release_drive,
    signal_drive,
    situation_drive,
    slack_ends,
)

HEAVY, LIGHT = 8.131, 3.096


def _pair(
    stand: StandConfig, x: np.ndarray, mass: float, spec: EffectSpec, params: str = "final"
) -> tuple[StandParams, SimResult, ModelRun]:
    """The stand, its baseline run and its run with one effect."""
    p = stand.stand_params(params, mass)
    return p, Model(p).run(x, RATE), Model(p, [spec]).run(x, RATE)


# --- measurement effects -------------------------------------------------------------


@pytest.mark.parametrize("name", ["11", "12a"])
def test_dial_gauge_gain_scales_u_and_leaves_force_bit_identical(
    stand: StandConfig, name: str
) -> None:
    x, mass = situation_drive(stand, name)
    spec = EffectSpec("dial_gauge_calibration", {"gain_error": 0.02, "offset_m": 1e-4})
    _, base, run = _pair(stand, x, mass, spec)
    assert np.array_equal(run.force_n, base.force_n)
    assert np.allclose(run.u_m - base.u_m, 0.02 * base.u_m + 1e-4, rtol=0, atol=1e-15)


def test_force_gauge_dynamics_delays_peaks_and_attenuates_fast_features(
    stand: StandConfig,
) -> None:
    x, mass = situation_drive(stand, "10")
    _, base, run = _pair(stand, x, mass, EffectSpec("force_gauge_dynamics"))
    assert np.array_equal(run.u_m, base.u_m)
    ends = slack_ends(base.force_n)
    assert ends.size >= 3
    # Low-frequency delay of ω²/(s² + 2ζωs + ω²) is 2ζ/ω: 2.8 ms = 5.6 samples at 80 Hz, ζ 0.7.
    expected = 2 * 0.7 / (2 * math.pi * 80.0) * RATE
    assert abs(best_lag(run.force_n, base.force_n) - expected) <= 1.0
    for e in ends:
        window = slice(e, e + 200)
        delay = np.argmax(run.force_n[window]) - np.argmax(base.force_n[window])
        assert 3 <= delay <= 8
    # The tension jump c·δ̇ at each re-tension is smoothed (a 2nd-order lag starts flat).
    for e in ends:
        assert run.force_n[e + 1] - run.force_n[e] < 0.3 * (base.force_n[e + 1] - base.force_n[e])
    assert run.force_n[-1] == pytest.approx(base.force_n[-1], abs=1e-3)  # DC gain 1 (creeping)
    # A slower, critically damped gauge (40 Hz, |H(11 Hz)| = 0.93) cuts the ≈ 11 Hz snatch
    # humps themselves, though only by a few per cent: the delay is the main signature.
    slow_gauge = EffectSpec("force_gauge_dynamics", {"cutoff_hz": 40.0, "damping_ratio": 1.0})
    _, _, low = _pair(stand, x, mass, slow_gauge)
    for e in ends:
        window = slice(e, e + 200)
        assert low.force_n[window].max() < 0.985 * base.force_n[window].max()


def test_channel_time_skew_shifts_the_cross_correlation_peak(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "11")
    spec = EffectSpec("channel_time_skew", {"force_skew_s": 1e-3, "displacement_skew_s": -1.5e-3})
    _, base, run = _pair(stand, x, mass, spec)
    assert best_lag(run.force_n, base.force_n) == 2
    assert best_lag(np.gradient(run.u_m), np.gradient(base.u_m)) == -3
    # Residual ≈ −Δt·dF/dt (first order in the skew).
    residual = run.force_n - base.force_n
    assert np.corrcoef(residual, -1e-3 * np.gradient(base.force_n, 1 / RATE))[0, 1] > 0.98


# --- fibre effects --------------------------------------------------------------------


@pytest.mark.parametrize("mass", [HEAVY, LIGHT])
def test_viscoelastic_raises_the_catch_peak(stand: StandConfig, mass: float) -> None:
    # The fibre slackens once and catches the sliding weight: a quick event.
    _, base, run = _pair(stand, release_drive(), mass, EffectSpec("fibre_viscoelastic"))
    assert run.force_n.max() > 1.03 * base.force_n.max()


def test_viscoelastic_leaves_quasi_static_motion_alone(stand: StandConfig) -> None:
    slow = signal_drive(stand, SignalSpec(Shape.QUASI_SINUSOIDAL, 0.040, 0.1, cycles=1))
    spec = EffectSpec("fibre_viscoelastic")
    # Frictionless guide: the fibre's strain rate stays tiny, so does the branch force.
    _, base, run = _pair(stand, slow, HEAVY, spec, params="starting")
    assert np.abs(run.force_n - base.force_n).max() < 0.1
    _, quick_base, quick = _pair(stand, release_drive(), HEAVY, spec, params="starting")
    assert quick.force_n.max() - quick_base.force_n.max() > 3.0
    # With guide friction the weight sticks at reversals while the drive turns (δ̇ = ẋ):
    # the branch shows there, still a small share of the force swing.
    _, base, run = _pair(stand, slow, HEAVY, spec)
    assert np.abs(run.force_n - base.force_n).max() < 0.1 * np.ptp(base.force_n)


@pytest.mark.parametrize("mass", [HEAVY, LIGHT])
def test_string_modes_ring_at_the_predicted_tension_dependent_frequency(
    stand: StandConfig, mass: float
) -> None:
    # Free vibration about rest (weakly damped, drive held): the kernel's own state is set.
    from sim.physics import compose
    from sim.physics.runs import friction_arrays, parameter_row

    p = stand.stand_params("starting", mass)
    spec = EffectSpec("fibre_transverse_vibration", {"damping_ratio": 1e-4})
    kernel = compose.union()
    c = kernel.pack(parameter_row(p, [spec]), *friction_arrays(p.friction))
    state = np.array(kernel.rest_state(c))
    state[kernel.Y_A2] += 2e-3  # pluck the weight span by 2 mm
    n = 8000
    out = [np.empty(n) for _ in range(4)]
    kernel.advance_into(np.zeros(n), 1 / RATE, 1, c, state, *out)
    u, force = out[0][1:], out[2][1:]
    spectrum = np.abs(np.fft.rfft((force - force.mean()) * np.hanning(n - 1)))
    freq = np.fft.rfftfreq(n - 1, 1 / RATE)
    f2 = 1 / (2 * p.free_length_m) * math.sqrt(p.preload_tension_n / p.linear_density_kg_m)
    # Tension ripple at 2f (a² term) and at f (the static gravity sag makes it linear too).
    for target in (f2, 2 * f2):
        near = (freq > 0.8 * target) & (freq < 1.2 * target)
        assert freq[near][np.argmax(spectrum[near])] == pytest.approx(target, rel=0.01)
    assert np.abs(u).max() < 2e-5  # the weight barely notices


def test_string_ripple_follows_snatches_and_spares_displacement(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "11")
    p, base, run = _pair(stand, x, mass, EffectSpec("fibre_transverse_vibration"))
    residual = run.force_n - base.force_n
    first = slack_ends(base.force_n)[0]
    assert np.abs(residual[: first - 200]).max() < 1e-3  # nothing before the first slack
    # Right after the first snatch: a ripple near 2f of the weight span at the mean tension.
    window = slice(first + 4, first + 84)
    ripple = residual[window] - np.convolve(residual, np.ones(9) / 9, "same")[window]
    spectrum = np.abs(np.fft.rfft(ripple * np.hanning(ripple.size), n=4096))
    freq = np.fft.rfftfreq(4096, 1 / RATE)
    tension = run.true_force_n[window].clip(min=0).mean()
    f2 = 1 / (2 * p.free_length_m) * math.sqrt(tension / p.linear_density_kg_m)
    assert freq[np.argmax(spectrum)] == pytest.approx(2 * f2, rel=0.25)
    assert np.abs(run.u_m - base.u_m).max() < 0.005 * np.ptp(base.u_m)
    slow, slow_mass = situation_drive(stand, "12a")  # taut throughout: strings stay quiet
    _, slow_base, slow_run = _pair(stand, slow, slow_mass, EffectSpec("fibre_transverse_vibration"))
    assert np.abs(slow_run.force_n - slow_base.force_n).max() < 0.01


def _length_offset(p: StandParams, x: np.ndarray, run: ModelRun) -> np.ndarray:
    """Effective length offset L, reconstructed from the recorded channels (taut samples).

    F = k·(δ₀ + x − n·u + L) + c·(ẋ − n·v), with ẋ the sample interval's rate.
    """
    rel = x - x[0]
    xd = np.concatenate([[0.0], np.diff(rel) * RATE])
    n = p.projection
    length = (run.force_n - p.damping_n_s_m * (xd - n * run.v_m_s)) / p.stiffness_n_m
    return np.asarray(length - (p.preload_m + rel - n * run.u_m))


@pytest.mark.parametrize("params", ["starting", "final"])
def test_pulley_jump_changes_the_fibre_length_only_across_slack_episodes(
    stand: StandConfig, params: str
) -> None:
    x, mass = situation_drive(stand, "11")
    spec = EffectSpec("fibre_pulley_jump")
    p, base, run = _pair(stand, x, mass, spec, params)
    length = _length_offset(p, x, run)
    taut = run.force_n > 0
    first = int(np.argmax(~taut))
    assert np.array_equal(run.u_m[:first], base.u_m[:first])  # identical until the first slack
    # Within each taut phase L is constant; it changes only from one phase to the next.
    phase = np.cumsum(np.diff(taut.astype(int), prepend=1) == 1)
    levels = []
    for k in np.unique(phase[taut]):
        values = length[taut & (phase == k)]
        assert np.ptp(values) < 1e-9
        levels.append(values.mean())
    assert levels[0] == pytest.approx(0.0, abs=1e-10)
    assert np.abs(np.diff(levels)).max() > 0.5e-4  # real steps …
    assert np.all((np.array(levels) > -1e-9) & (np.array(levels) < 2e-4 + 1e-9))  # … between seats
    slow, slow_mass = situation_drive(stand, "12a")  # never slack: never jumps
    _, slow_base, slow_run = _pair(stand, slow, slow_mass, spec, params)
    assert np.array_equal(slow_run.u_m, slow_base.u_m)


def _seat_levels(stand: StandConfig, spec: EffectSpec) -> list[float]:
    """The effective length offset L of each taut phase of situation 11 (slack each cycle)."""
    x, mass = situation_drive(stand, "11")
    p, _, run = _pair(stand, x, mass, spec)
    length = _length_offset(p, x, run)
    taut = run.force_n > 0
    phase = np.cumsum(np.diff(taut.astype(int), prepend=1) == 1)
    return [float(length[taut & (phase == k)].mean()) for k in np.unique(phase[taut])]


def test_a_fibre_climbing_the_flank_steps_up_to_the_flange_and_stays(
    stand: StandConfig,
) -> None:
    # A snap jump (depth scale ≪ the slack loops): every episode moves the seat by a
    # whole step. Two grooves toggle between 0 and the step; a flank of two steps climbs
    # 0 → step → 2·step and stays at the flange.
    step = 3e-4
    snap = {"step_m": step, "depth_scale_m": 1e-6}
    toggle = np.array(_seat_levels(stand, EffectSpec("fibre_pulley_jump", snap)))
    flank = np.array(_seat_levels(stand, EffectSpec("fibre_pulley_jump", {**snap, "seats": 2.0})))
    assert toggle.size > 4 and flank.size > 4
    assert np.allclose(toggle[:4], [0.0, step, 0.0, step], atol=2e-6)
    assert np.allclose(flank[:3], [0.0, step, 2 * step], atol=2e-6)
    assert np.allclose(flank[3:], 2 * step, atol=2e-6)  # never past the flange, never back


def test_the_fibre_stays_in_its_groove_until_the_slack_reaches_the_onset(
    stand: StandConfig,
) -> None:
    # Slack every cycle: with the onset deeper than any slack loop the seat never moves
    # (the baseline, bit for bit); with no onset it jumps.
    x, mass = situation_drive(stand, "11")
    deep = EffectSpec("fibre_pulley_jump", {"step_m": 1e-3, "onset_m": 0.04})
    _, base, run = _pair(stand, x, mass, deep)
    assert run.slack.any()
    assert np.array_equal(run.u_m, base.u_m)
    _, _, jumping = _pair(stand, x, mass, EffectSpec("fibre_pulley_jump", {"step_m": 1e-3}))
    assert np.abs(jumping.force_n - base.force_n).max() > 1.0


def test_the_fibre_leaves_its_groove_only_after_lying_slack_for_the_dwell(
    stand: StandConfig,
) -> None:
    # Situation 11 goes slack every cycle, each episode far shorter than a second: a dwell
    # longer than every episode keeps the seat (the baseline, bit for bit); a dwell
    # shorter than the longest episode moves it, but later than no dwell does.
    x, mass = situation_drive(stand, "11")
    step = {"step_m": 1e-3, "depth_scale_m": 1e-5}
    _, base, never = _pair(
        stand, x, mass, EffectSpec("fibre_pulley_jump", {**step, "dwell_s": 0.9})
    )
    assert never.slack.any()
    assert np.array_equal(never.u_m, base.u_m)
    slack = base.slack.astype(int)
    starts, ends = np.flatnonzero(np.diff(slack) == 1), np.flatnonzero(np.diff(slack) == -1)
    longest = max(e - s for s, e in zip(starts, ends[ends > starts[0]], strict=False)) / RATE
    dwell = 0.5 * longest
    _, _, late = _pair(stand, x, mass, EffectSpec("fibre_pulley_jump", {**step, "dwell_s": dwell}))
    _, _, early = _pair(stand, x, mass, EffectSpec("fibre_pulley_jump", step))
    first_change = [int(np.argmax(np.abs(r.force_n - base.force_n) > 1e-6)) for r in (early, late)]
    assert np.abs(late.force_n - base.force_n).max() > 1.0
    # The jump waits for the dwell: not before the first slack sample plus the dwell.
    first_slack = int(np.argmax(base.slack))
    assert first_change[1] >= first_slack + round(dwell * RATE) - 1
    assert first_change[0] < first_change[1]


def test_every_fitting_range_lies_within_what_the_model_admits() -> None:
    from sim.effects import EFFECTS

    for info in EFFECTS.values():
        for q in info.params:
            # Strictly inside where it is not an exact zero: a log-scale fit that ends on
            # its bound comes back a rounding error beyond it.
            assert q.minimum < q.fit_low or q.fit_low == q.minimum == 0.0, (info.name, q.name)
            assert q.fit_low < q.fit_high < q.maximum, (info.name, q.name)
            assert q.fit_low <= q.low <= q.high <= q.fit_high, (info.name, q.name)
            assert q.why or not q.fit, (info.name, q.name)


# --- pulley and guide -----------------------------------------------------------------


def test_pulley_friction_makes_force_hysteresis_between_pull_and_return(
    stand: StandConfig,
) -> None:
    from drivers.signals import plan_motion
    from sim.situations import SITUATIONS

    profile = plan_motion(SITUATIONS["12a"].signal, stand.drive)
    t, x = profile.sample(RATE)
    p, base, run = _pair(stand, x, HEAVY, EffectSpec("pulley_inertia_friction"))
    xd = profile.velocity_m_s(t)
    pull, back = xd > 0.5 * xd.max(), xd < 0.5 * xd.min()
    # Bearing friction at the rim: M₀/r + μ_L·(T₁ + T₂)·sin(φ/2), defaults 0.01 N·m, 0.005.
    bearing = 0.01 / p.pulley_radius_m + 0.005 * math.sin(math.radians(62)) * 2 * base.force_n
    excess = run.force_n - base.force_n  # the gauge sits on the drive side
    assert excess[pull].mean() == pytest.approx(bearing[pull].mean(), rel=0.1)
    assert excess[back].mean() == pytest.approx(-bearing[back].mean(), rel=0.1)
    # Force balance on the pulley in steady pulling: T₁ − T₂ = bearing friction.
    across = run.true_force_n - run.weight_force_n
    assert across[pull].mean() == pytest.approx(bearing[pull].mean(), rel=0.05)


def test_pulley_inertia_loads_the_drive_side_with_the_drive_acceleration(
    stand: StandConfig,
) -> None:
    from drivers.signals import plan_motion

    profile = plan_motion(SignalSpec(Shape.QUASI_SINUSOIDAL, 0.020, 2.0, cycles=3), stand.drive)
    t, x = profile.sample(RATE)
    j = 3e-4
    spec = EffectSpec(
        "pulley_inertia_friction", {"inertia_kg_m2": j, "bearing_torque_n_m": 0, "load_coeff": 0}
    )
    p, base, run = _pair(stand, x, HEAVY, spec)
    assert not base.slack.any()
    inertial = j / p.pulley_radius_m**2 * profile.accel_m_s2(t)  # (J/r²)·ẍ
    across = run.true_force_n - run.weight_force_n
    moving = (t > 0.6) & (t < 2.0)
    slope, _ = np.polyfit(inertial[moving], across[moving], 1)
    assert slope == pytest.approx(1.0, rel=0.1)
    assert np.corrcoef(inertial[moving], across[moving])[0, 1] > 0.85


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_side_load_friction_balance_while_sliding_steadily(
    stand: StandConfig, direction: float
) -> None:
    p = stand.stand_params("final", HEAVY)
    t = np.arange(int(8 * RATE)) / RATE
    mu = 0.1
    run = Model(p, [EffectSpec("side_load_friction", {"friction_coeff": mu})]).run(
        direction * 0.02 * t, RATE
    )
    steady = t > 6.0
    v = direction * 0.02 / p.projection
    table = float(p.friction.force_n(np.array([v]), p.normal_force_n)[0])  # type: ignore[union-attr]
    sin_beta = p.lateral_offset_m / p.free_length_m
    # n·T = m·g·sin α + F_f(v) + μ_s·T·sin β·sign(v)
    expected = (p.gravity_along_n + table) / (p.projection - direction * mu * sin_beta)
    assert run.force_n[steady].mean() == pytest.approx(expected, rel=1e-4)


def test_side_load_friction_vanishes_while_slack(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "11")
    p, base, run = _pair(stand, x, mass, EffectSpec("side_load_friction", {"friction_coeff": 0.3}))
    slack = run.true_force_n <= 0
    interior = slack & np.roll(slack, 1) & np.roll(slack, -1) & np.roll(slack, 2)
    assert interior.sum() > 50
    # In free flight the weight obeys m·v̇ = −m·g·sin α − F_f(v): no side load at all.
    accel = np.diff(run.v_m_s) * RATE
    v_mid = 0.5 * (run.v_m_s[1:] + run.v_m_s[:-1])
    friction = p.friction.force_n(v_mid, p.normal_force_n * p.friction_scale)  # type: ignore[union-attr]
    law = (-p.gravity_along_n - friction) / p.mass_kg
    inside = interior[1:] & interior[:-1] & (np.abs(v_mid) > 2 * p.friction.v_reg_m_s)  # type: ignore[union-attr]
    side_at_rest = 0.3 * p.lateral_offset_m / p.free_length_m * p.preload_tension_n / p.mass_kg
    assert np.abs(accel[inside] - law[inside]).max() < 0.01 * side_at_rest
    taut = ~slack
    assert np.abs(run.force_n[taut] - base.force_n[taut]).max() > 1.0  # it does act when taut


# --- stick-slip -----------------------------------------------------------------------


def test_stick_slip_breaks_away_at_static_friction(stand: StandConfig) -> None:
    p = stand.stand_params("final", HEAVY)
    t = np.arange(int(1.0 * RATE)) / RATE
    x = 0.002 * t  # a slow pull from rest
    base = Model(p).run(x, RATE)
    run = Model(p, [EffectSpec("stick_slip_friction", {"static_ratio": 0.4})]).run(x, RATE)
    kinetic = p.normal_force_n * p.friction.mu[0]  # type: ignore[union-attr]
    n = p.projection
    assert run.force_n.max() == pytest.approx((p.gravity_along_n + 1.4 * kinetic) / n, rel=0.01)
    assert base.force_n.max() == pytest.approx((p.gravity_along_n + kinetic) / n, rel=0.02)


def test_stick_slip_shows_at_low_speed_not_in_fast_sliding(stand: StandConfig) -> None:
    p = stand.stand_params("final", HEAVY)
    t = np.arange(int(6 * RATE)) / RATE
    late = t > 4.0
    spreads = {}
    for speed in (0.002, 0.05):
        x = speed * t
        base = Model(p).run(x, RATE)
        run = Model(p, [EffectSpec("stick_slip_friction")]).run(x, RATE)
        spreads[speed] = (np.std(run.force_n[late]), np.std(base.force_n[late]))
        if speed == 0.05:  # LuGre's steady sliding friction is the table's
            assert run.force_n[late].mean() == pytest.approx(base.force_n[late].mean(), rel=2e-3)
    slow_run, slow_base = spreads[0.002]
    assert slow_run > 0.3 > 10 * slow_base  # sticking and slipping: the force saws


@pytest.mark.parametrize("exponent", [0.5, 1.0])
def test_sliding_friction_follows_the_stribeck_curve(stand: StandConfig, exponent: float) -> None:
    # Newton on the weight gives its friction from the recorded channels, sample by sample:
    # f = n·F − m·g·sin α − m·a. Sliding (bristles settled within milliseconds), LuGre's
    # friction is its Stribeck curve g(v) = f_table(v)·(1 + r·e^(−|v/v_s|^δ)). (The
    # Gaussian, δ = 2, falls so steeply that the weight slides in stick-slip bursts here,
    # its bristles never settled: the curves that fall gently are the ones to read.)
    p = stand.stand_params("final", HEAVY)
    n, m = p.projection, p.mass_kg
    t = np.arange(int(2.0 * RATE)) / RATE
    x = 0.5 * 0.1 * t**2  # the drive accelerates: the weight sweeps the curve's speeds
    ratio, v_s = 0.8, 0.04
    params = {"static_ratio": ratio, "stribeck_speed_m_s": v_s, "stribeck_exponent": exponent}
    shares = []
    for run in (
        Model(p).run(x, RATE),
        Model(p, [EffectSpec("stick_slip_friction", params)]).run(x, RATE),
    ):
        v = run.v_m_s
        friction = n * run.force_n - p.gravity_along_n - m * np.gradient(v, 1.0 / RATE)
        table = p.friction.force_n(v, p.normal_force_n) * p.friction_scale  # type: ignore[union-attr]
        sliding = (v > 0.5 * v_s) & (v < 4 * v_s) & (t > 0.5)  # after the breakaway
        assert sliding.sum() > 200
        shares.append((friction[sliding] / table[sliding] - 1.0, v[sliding]))
    (base_excess, _), (excess, v) = shares
    assert np.abs(base_excess).max() < 0.02  # the plain table
    expected = ratio * np.exp(-((v / v_s) ** exponent))
    error = np.abs(excess - expected) / ratio
    assert np.median(error) < 0.01
    assert np.percentile(error, 95) < 0.03


def test_stick_slip_residual_starts_at_the_drive_reversals_of_a_slow_test(
    stand: StandConfig,
) -> None:
    x, mass = situation_drive(stand, "12a")
    _, base, run = _pair(stand, x, mass, EffectSpec("stick_slip_friction"))
    residual = np.abs(run.force_n - base.force_n)
    xd = np.diff(x, prepend=x[0])
    edges = np.flatnonzero(np.diff((np.abs(xd) > 1e-9).astype(int)) != 0)
    first_edge = edges[0]
    assert residual[: first_edge - 1].max() < 1e-9  # at rest before the motion
    big = np.flatnonzero(residual > 0.5 * residual.max())
    distance = np.min(np.abs(big[:, None] - edges[None, :]), axis=1) / RATE
    assert np.all(distance < 0.3)  # its largest values sit at starts, stops and reversals


def test_gauge_filter_is_the_exact_discretisation_of_the_low_pass() -> None:
    from scipy import signal

    from sim.effects.measure import gauge_filter_into

    rng = np.random.default_rng(2)
    force = 40.0 + np.cumsum(rng.normal(0, 1.0, 3000))
    w, zeta = 2 * math.pi * 55.0, 0.6
    t = np.arange(force.size) / RATE
    system = signal.StateSpace([[0, 1], [-w * w, -2 * zeta * w]], [[0], [w * w]], [[1, 0]], [[0]])
    _, expected, _ = signal.lsim(system, force, t, X0=[force[0], 0.0])  # linear between samples
    out = np.empty_like(force)
    gauge_filter_into(force, 1 / RATE, 55.0, zeta, np.array([force[0], 0.0, force[0]]), out)
    assert np.abs(out - expected).max() < 1e-8 * np.abs(force).max()
