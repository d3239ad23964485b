"""Multiple shooting from measured states: segmentation, state estimation, exact restarts."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import StandConfig, default_config
from sim.effects import EffectSpec
from sim.identify.fitting import Candidate, simulate_values
from sim.identify.shooting import dial_slope, segment_trace
from sim.identify.traces import Trace, make_trace
from sim.model import Model, Restarts
from sim.physics import compose, layout
from sim.physics.runs import friction_arrays, parameter_row, simulate, simulate_segments
from sim.physics.starts import start_states

QUICK = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=3, ramp_fraction=0.4)
SLOW = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.060, 0.5, cycles=2)
BASE = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}


@pytest.fixture(scope="module")
def stand() -> StandConfig:
    return default_config()


def _trace(
    stand: StandConfig,
    mass: float,
    effects: list[EffectSpec],
    noise_u: float = 0.0,
    seed: int = 0,
    signal: SignalSpec = QUICK,
) -> tuple[Trace, np.ndarray]:
    t, x = plan_motion(signal, stand.drive).sample(stand.sample_rate_hz)
    run = Model(stand.stand_params("final", mass), effects).run(x, stand.sample_rate_hz)
    u = run.u_m + np.random.default_rng(seed).normal(0.0, noise_u, x.size)
    return make_trace("quick", t, x, u, run.force_n, mass), run.v_m_s


def test_segments_tile_the_trace_and_start_calm(stand: StandConfig) -> None:
    tr, _ = _trace(stand, 3.096, [])
    seg = segment_trace(tr)
    assert seg.body[0] == 0 and seg.starts[0] == 0
    assert np.all(np.diff(seg.body) > 0)
    # Every sample belongs to exactly one body, and its run covers it.
    assert seg.seg_of.size == tr.samples
    assert np.all(seg.offset >= 0) and np.all(seg.offset < seg.lengths[seg.seg_of])
    # Later segments start with a warm-up before their body, mostly on a taut fibre.
    assert np.all(seg.starts[1:] < seg.body[1:])
    assert np.mean(tr.force_n[seg.starts[1:]] > 0.0) > 0.7


def test_a_segment_from_the_true_state_reproduces_the_open_loop_run(stand: StandConfig) -> None:
    params = stand.stand_params("final", 3.096)
    _, x = plan_motion(QUICK, stand.drive).sample(stand.sample_rate_hz)
    run = Model(params).run(x, stand.sample_rate_hz)
    rel = x - x[0]
    starts = np.array([0, 700, 1500], dtype=np.int64)
    lengths = np.array([700, 900, 600], dtype=np.int64)
    init = np.zeros((1, starts.size, layout.N_INIT))
    init[0, 1:, layout.I_U] = run.u_m[starts[1:]]
    init[0, 1:, layout.I_V] = run.v_m_s[starts[1:]]
    init[0, :, layout.I_F] = run.force_n[starts]
    row = parameter_row(params)[None, :]
    u, f = simulate_segments(rel, stand.sample_rate_hz, row, params.friction, starts, lengths, init)
    for k, (s, n) in enumerate(zip(starts, lengths, strict=True)):
        np.testing.assert_allclose(u[0, k, :n], run.u_m[s : s + n], atol=1e-9)
        np.testing.assert_allclose(f[0, k, :n], run.force_n[s : s + n], atol=1e-4)


def test_kernel_segment_zero_is_the_open_loop_run(stand: StandConfig) -> None:
    params = stand.stand_params("final", 8.131)
    _, x = plan_motion(QUICK, stand.drive).sample(stand.sample_rate_hz)
    rel = x - x[0]
    n = rel.size
    run = simulate(rel, stand.sample_rate_hz, params)
    su, sf = simulate_segments(
        rel,
        stand.sample_rate_hz,
        parameter_row(params)[None, :],
        params.friction,
        np.array([0]),
        np.array([n]),
        np.zeros((1, 1, layout.N_INIT)),
    )
    np.testing.assert_array_equal(su[0, 0], run.u_m)
    np.testing.assert_array_equal(sf[0, 0], run.force_n)


def test_state_estimation_error_is_bounded_under_noise(stand: StandConfig) -> None:
    noise = 5e-6
    tr, v_true = _trace(stand, 8.131, [], noise_u=noise, seed=3)
    clean, _ = _trace(stand, 8.131, [])
    seg = segment_trace(tr)
    idx = seg.starts[1:]
    du = seg.u_m[idx] - clean.u_m[idx]
    dv = seg.v_m_s[idx] - v_true[idx]
    assert np.sqrt(np.mean(du**2)) < 0.8 * noise  # smoothing beats the raw sample
    # A cubic fit over ±5 ms: σ_v ≈ σ_u·√(75/(N³·dt²))… well under 5 mm/s here.
    assert np.sqrt(np.mean(dv**2)) < 5e-3


@pytest.mark.parametrize("mass", [3.096, 8.131])
def test_restarts_take_the_displacement_on_the_dial_gauges_own_scale(
    stand: StandConfig, mass: float
) -> None:
    # The gauge reads 3 % high; the recordings show it (u against the drive at constant
    # force, calm samples of all traces), so every candidate restarts from the true u.
    from sim.checks.check import SMALL_CAMPAIGN, make_campaign

    rng = np.random.default_rng(7)
    traces, _, params = make_campaign(stand, "dial_gauge_calibration", mass, rng, SMALL_CAMPAIGN)
    p = stand.stand_params("final", mass)
    slope = dial_slope(traces)
    assert slope * p.projection == pytest.approx(1 + params["gain_error"], abs=3e-4)
    tr = traces[0]
    seg = segment_trace(tr)
    row = parameter_row(p)[None, :]
    x_rel = tr.x_m - tr.x_m[0]
    init = start_states(
        row, x_rel, tr.rate_hz, seg.starts, seg.u_m, seg.v_m_s, seg.force_n, slope
    ).init
    expected = seg.u_m[seg.starts] / (slope * p.projection)
    np.testing.assert_allclose(init[0, :, layout.I_U], expected)
    # Without the campaign's estimate (a lone quick trace has too few calm samples) the
    # reading is taken at face value.
    if not np.isfinite(seg.dial_slope):
        channels = (seg.starts, seg.u_m, seg.v_m_s, seg.force_n)
        init = start_states(row, x_rel, tr.rate_hz, *channels).init
        np.testing.assert_allclose(init[0, :, layout.I_U], seg.u_m[seg.starts])


def test_rows_of_one_batch_get_the_start_states_each_would_get_alone(stand: StandConfig) -> None:
    # start_states computes the true channels once for rows whose channel transforms
    # agree; a skewed row (its own true channels) and plain rows share one call.
    p = stand.stand_params("final", 3.096)
    tr, _ = _trace(stand, 3.096, [])
    seg = segment_trace(tr)
    x_rel = tr.x_m - tr.x_m[0]
    skews = [{"force_skew_s": 0.004, "displacement_skew_s": -0.002}, {"force_skew_s": -0.006}]
    rows = np.stack(
        [parameter_row(p)]
        + [parameter_row(p, [EffectSpec("channel_time_skew", s)]) for s in skews]
        + [parameter_row(p, [EffectSpec("fibre_viscoelastic")])]
    )
    args = (x_rel, tr.rate_hz, seg.starts, seg.u_m, seg.v_m_s, seg.force_n, 1.01 / p.projection)
    together = start_states(rows, *args).init
    for b, row in enumerate(rows):
        np.testing.assert_array_equal(together[b], start_states(row[None, :], *args).init[0])
    # The skewed rows start elsewhere than the plain one, and apart from each other.
    assert not np.array_equal(together[1, :, layout.I_F], together[0, :, layout.I_F])
    assert not np.array_equal(together[1, :, layout.I_F], together[2, :, layout.I_F])


def test_the_friction_table_arrays_are_the_callers_own(stand: StandConfig) -> None:
    # The interpolant is built once per table; a caller that writes into its arrays must
    # not change what the next run gets.
    table = stand.stand_params("final", 3.096).friction
    knots, coef = friction_arrays(table)
    knots[:] = 0.0
    coef[:] = 0.0
    again_knots, again_coef = friction_arrays(table)
    np.testing.assert_array_equal(again_knots, table.pchip().x)
    np.testing.assert_array_equal(again_coef, table.pchip().c)


@pytest.mark.parametrize("gain", [0.05, -0.137])
def test_a_dial_gauge_error_stays_in_the_displacement_channel(
    stand: StandConfig, gain: float
) -> None:
    # The light weight goes slack every cycle, so every cycle restarts from the gauges.
    # Restarted from a dial gauge reading 5 % high, the baseline used to start each
    # segment with a wrong elongation (measured: force errors of 16 % of the force's
    # range). On the gauge's own scale its force stays right and the gauge's error shows
    # where it is: in u.
    dial = [EffectSpec("dial_gauge_calibration", {"gain_error": gain})]
    tr, _ = _trace(stand, 3.096, dial)
    slow, _ = _trace(stand, 3.096, dial, signal=SLOW)
    # One gauge, one campaign: the slow recording shows its scale (as in ``diagnose``).
    tr = dataclasses.replace(tr, dial_slope=dial_slope([tr, slow]))
    assert segment_trace(tr).count > 3
    nominal = stand.stand_params("final", 3.096)
    cand = Candidate.build("dial_gauge_calibration")
    values = dict(BASE, **{"dial_gauge_calibration.gain_error": gain})
    u, f = simulate_values(cand, [values], tr, nominal)
    ub, fb = simulate_values(Candidate.build(), [BASE], tr, nominal)
    spread_f, rms_u = np.ptp(tr.force_n), np.sqrt(np.mean(tr.u_m**2))
    rms = lambda a: float(np.sqrt(np.mean(a**2)))  # noqa: E731
    # The true model predicts both channels; the baseline's force nearly as well (its
    # starts, refined over each warm-up by both gauges, give a little to the reading it
    # lacks: 0.21 % of the force's range at 5 %) …
    assert rms(f[0] - tr.force_n) < 0.002 * spread_f
    assert rms(u[0] - tr.u_m) < 0.01 * abs(gain) * rms_u
    assert rms(fb[0] - tr.force_n) < 0.003 * spread_f
    # … and its displacement misses by the gauge's error.
    assert rms(ub[0] - tr.u_m) > 0.5 * abs(gain) * rms_u


def test_shooting_tames_the_light_weights_chaos(stand: StandConfig) -> None:
    # A 1e-6 stiffness change barely moves segment predictions (open loop: chaotic).
    tr, _ = _trace(stand, 3.096, [])
    nominal = stand.stand_params("final", 3.096)
    sets = [BASE, dict(BASE, stiffness_scale=1.0 + 1e-6)]
    u, _ = simulate_values(Candidate.build(), sets, tr, nominal)
    assert np.max(np.abs(u[0] - u[1])) < 1e-7


def test_restarts_only_after_slack(stand: StandConfig) -> None:
    # Taut all through (heavy weight, slow quasi-sine): one open-loop run, no restarts.
    slow = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.060, 0.5, cycles=2)
    t, x = plan_motion(slow, stand.drive).sample(stand.sample_rate_hz)
    run = Model(stand.stand_params("final", 8.131)).run(x, stand.sample_rate_hz)
    assert run.force_n.min() > 0.5 * run.preload_tension_n
    assert segment_trace(make_trace("slow", t, x, run.u_m, run.force_n, 8.131)).count == 1
    # Slack every cycle (light weight, quick): a boundary follows every slack episode.
    tr, _ = _trace(stand, 3.096, [])
    seg = segment_trace(tr)
    assert seg.count > 3
    slack = tr.force_n < 0.1 * np.median(tr.force_n)
    for prev, nxt in zip(seg.body[:-1], seg.body[1:], strict=True):
        assert slack[prev:nxt].any()


def test_chained_segments_equal_independent_ones_without_carried_states(
    stand: StandConfig,
) -> None:
    # With no string modes and no bristles nothing is carried: the chained kernel's
    # hand-over (a run split in two at the next start) must change nothing.
    params = stand.stand_params("final", 3.096)
    _, x = plan_motion(QUICK, stand.drive).sample(stand.sample_rate_hz)
    rel = np.ascontiguousarray(x - x[0])
    rows = np.stack(
        [parameter_row(params, [EffectSpec("fibre_viscoelastic")]), parameter_row(params)]
    )
    starts = np.array([0, 650, 1400], dtype=np.int64)
    lengths = np.array([700, 800, rel.size - 1400], dtype=np.int64)
    init = np.zeros((2, 3, layout.N_INIT))
    init[:, :, layout.I_F] = 30.0
    knots, coef = friction_arrays(params.friction)
    outs = []
    for fn in (compose.union().simulate_segments_into, compose.union().simulate_chained_into):
        u, f = np.empty((2, 3, int(lengths.max()))), np.empty((2, 3, int(lengths.max())))
        fn(
            rel, 1.0 / stand.sample_rate_hz, 1, rows, knots, coef, starts, lengths, init, u, f,
            np.zeros((2, 0)),
        )  # fmt: skip
        outs.append((u, f))
    np.testing.assert_allclose(outs[1][0], outs[0][0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(outs[1][1], outs[0][1], rtol=0, atol=1e-7)


@pytest.mark.parametrize(
    ("effect", "params"),
    [
        (None, {}),
        ("fibre_viscoelastic", {"branch_stiffness_n_m": 3.0e4, "relaxation_time_s": 0.05}),
        ("fibre_pulley_jump", {"step_m": 1.3e-4, "depth_scale_m": 1.0e-5, "dwell_s": 0.0123}),
        ("channel_time_skew", {"force_skew_s": -0.0203, "displacement_skew_s": -0.0117}),
        ("fibre_transverse_vibration", {}),  # carried from segment to segment: all run
    ],
)
def test_a_fit_simulates_only_the_segments_it_scores_and_gets_the_same_outputs(
    stand: StandConfig, effect: str | None, params: dict[str, float]
) -> None:
    # The fit scores the training cycles only; every segment restarts from measured
    # states, so the others need not run, nor a run past its last scored sample (plus
    # the samples that an early channel reads ahead: a negative skew).
    signal = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=6, ramp_fraction=0.4)
    spec = [EffectSpec(effect, params)] if effect else []
    tr, _ = _trace(stand, 3.096, spec, signal=signal)
    nominal = stand.stand_params("final", 3.096)
    cand = Candidate.build(effect) if effect else Candidate.build()
    values = dict(BASE, **{f"{effect}.{k}": v for k, v in params.items()})
    samples = np.flatnonzero(tr.train)[::4]
    full_u, full_f = simulate_values(cand, [values], tr, nominal)
    u, f = simulate_values(cand, [values], tr, nominal, samples=samples)
    np.testing.assert_array_equal(u, full_u[:, samples])
    np.testing.assert_array_equal(f, full_f[:, samples])
    restarts, _, _ = tr.segments.covering(samples)
    assert restarts.lengths.sum() < 0.8 * tr.segments.lengths.sum()


@pytest.mark.parametrize(
    ("effects", "values"),
    [
        (("fibre_transverse_vibration",), {}),
        (
            ("stick_slip_friction", "channel_time_skew"),
            {"channel_time_skew.force_skew_s": -0.0203},
        ),
    ],
)
def test_a_chained_model_runs_only_up_to_its_last_scored_sample(
    stand: StandConfig, effects: tuple[str, ...], values: dict[str, float]
) -> None:
    # States carried from segment to segment make every earlier run part of a sample's
    # history, but nothing after the last sample asked for (plus what an early channel
    # reads ahead) can change it: the runs stop there, with the same outputs.
    signal = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=6, ramp_fraction=0.4)
    tr, _ = _trace(stand, 3.096, [EffectSpec(e) for e in effects], signal=signal)
    nominal = stand.stand_params("final", 3.096)
    cand = Candidate.build(*effects)
    assert cand.model(nominal, 3.096).chained
    train = np.flatnonzero(tr.train)[::4]
    samples = train[: train.size // 2]
    full_u, full_f = simulate_values(cand, [dict(BASE, **values)], tr, nominal)
    u, f = simulate_values(cand, [dict(BASE, **values)], tr, nominal, samples=samples)
    np.testing.assert_array_equal(u, full_u[:, samples])
    np.testing.assert_array_equal(f, full_f[:, samples])
    restarts, _, _ = tr.segments.leading(samples)
    assert restarts.starts[0] == 0
    assert restarts.lengths.sum() < 0.7 * tr.segments.lengths.sum()


@pytest.mark.parametrize(
    "effects",
    [(), ("fibre_viscoelastic",), ("stick_slip_friction",), ("side_load_friction",)],
)
def test_the_serial_kernels_give_the_parallel_kernels_outputs_bit_for_bit(
    stand: StandConfig, effects: tuple[str, ...]
) -> None:
    # The traces of a one-set evaluation run side by side on the kernels' serial
    # variants: every (set, segment) item must come out as the parallel kernel computes
    # it (the baseline's kernel, the effects' kernel, the chained kernel).
    tr, _ = _trace(stand, 3.096, [EffectSpec(e) for e in effects])
    nominal = stand.stand_params("final", 3.096)
    cand = Candidate.build(*effects)
    sets = [dict(BASE), dict(BASE, stiffness_scale=1.2, friction_scale=0.7)]
    sets[1].update({p.name: p.to_natural(sum(p.bounds()) / 2) for p in cand.params[3:]})
    samples = np.flatnonzero(tr.train)[::4]
    for kw in ({}, {"samples": samples}):
        parallel = simulate_values(cand, sets, tr, nominal, **kw)  # type: ignore[arg-type]
        serial = simulate_values(cand, sets, tr, nominal, serial=True, **kw)  # type: ignore[arg-type]
        np.testing.assert_array_equal(serial[0], parallel[0])
        np.testing.assert_array_equal(serial[1], parallel[1])


def test_side_by_side_runs_items_in_threads_and_keeps_their_order() -> None:
    import threading

    import numba

    from sim.identify.side_by_side import side_by_side

    def work(k: int, serial: bool) -> tuple[int, bool, str]:
        return k, serial, threading.current_thread().name

    results = side_by_side(work, [1, 5, 3])
    assert [r[0] for r in results] == [0, 1, 2]
    threaded = numba.get_num_threads() > 1
    assert all(r[1] is threaded for r in results)
    assert all(r[2].startswith("trace") is threaded for r in results)
    assert side_by_side(work, [4]) == [(0, False, threading.current_thread().name)]


def test_the_jacobian_reuses_the_residuals_least_squares_just_asked_for(
    stand: StandConfig,
) -> None:
    # least_squares evaluates the residuals at a point, then its Jacobian there: the
    # forward differences take the memoised residuals instead of simulating them again.
    from sim.identify.fitting import Objective

    tr, _ = _trace(stand, 3.096, [EffectSpec("fibre_viscoelastic")])
    nominal = stand.stand_params("final", 3.096)
    cand = Candidate.build("fibre_viscoelastic")
    z = np.array([p.to_internal(0.5 * (p.low + p.high)) for p in cand.params])
    cold = Objective(cand, [tr], nominal)
    j_cold = cold.jacobian(z)
    warm = Objective(cand, [tr], nominal)
    warm.residuals(z)
    before = warm.simulations
    j_warm = warm.jacobian(z)
    np.testing.assert_array_equal(j_warm, j_cold)
    assert warm.simulations - before == z.size == cold.simulations - 1


def _restarted_and_open_loop_errors(
    stand: StandConfig, effect: str, params: dict[str, float]
) -> tuple[float, float]:
    """Held-out errors of the true model on its own clean light-weight quick recording:
    restarted from the recording's states (multiple shooting), and in one open-loop run,
    both in units of the error a real recording's gauge noise alone gives (0.5 µm,
    0.02 N: the simulated stand's). A clean recording's drive passes unfiltered, so one
    run is exact; a restart leaves the local fit's bias, well under that unit.
    """
    from sim.identify.heldout import Outputs, heldout_error, noise_floor

    tr, _ = _trace(stand, 3.096, [EffectSpec(effect, params)])
    assert segment_trace(tr).count > 3
    values = dict(BASE, **{f"{effect}.{k}": v for k, v in params.items()})
    nominal = stand.stand_params("final", 3.096)
    unit = noise_floor([dataclasses.replace(tr, noise_u_m=5e-7, noise_force_n=0.02)])
    restarted, open_loop = (
        heldout_error([tr], [Outputs(u[0], f[0])]) / unit
        for u, f in (
            simulate_values(Candidate.build(effect), [values], tr, nominal, shooting=shooting)
            for shooting in (True, False)
        )
    )
    return restarted, open_loop


def test_string_modes_carry_over_so_a_ringing_fibre_restarts_right(
    stand: StandConfig,
) -> None:
    # A clean recording of the true model with ringing spans (light weight, slack every
    # cycle). The spans' phase is invisible at a restart: carried over from the previous
    # segment's run they leave 12 noise units (an error that compounds from segment to
    # segment: 2.7 µm in the first, 52 µm in the sixth), restarted at static sag 150.
    effect, params = "fibre_transverse_vibration", {"damping_ratio": 0.012, "load_scale": 0.6}
    from sim.identify.heldout import Outputs, heldout_error, noise_floor

    tr, _ = _trace(stand, 3.096, [EffectSpec(effect, params)])
    seg = segment_trace(tr)
    model = Model(stand.stand_params("final", 3.096), [EffectSpec(effect, params)])
    assert model.chained
    unit = noise_floor([dataclasses.replace(tr, noise_u_m=5e-7, noise_force_n=0.02)])
    errors = []
    for chained in (True, False):
        model.chained = chained
        u, f = model.run_segments(tr.x_m, tr.rate_hz, seg.restarts)
        outputs = Outputs(seg.assemble(u)[0], seg.assemble(f)[0])
        errors.append(heldout_error([tr], [outputs]) / unit)
    carried, at_sag = errors
    assert carried < 0.2 * at_sag


@pytest.mark.parametrize(
    "params",
    [
        {"step_m": 1.3e-4, "depth_scale_m": 3.1e-3},  # a slide, deeper slack moves it further
        {"step_m": 1.3e-4, "depth_scale_m": 1.0e-5, "dwell_s": 0.0123},  # a snap after a dwell
    ],
)
def test_the_pulley_seat_follows_the_recorded_slack_so_restarts_keep_the_right_groove(
    stand: StandConfig, params: dict[str, float]
) -> None:
    # The seat toggles between two grooves on slack episodes; a restart cannot see which
    # (a tenth of a millimetre in a noisy elongation), but the recording holds every
    # episode that moved it. Set from the recorded episodes, the true model predicts a
    # clean recording well within a real recording's noise (0.003 and 1e-6 noise units;
    # a seat estimated from the elongation at each restart cost 340x one open-loop run).
    restarted, _ = _restarted_and_open_loop_errors(stand, "fibre_pulley_jump", params)
    assert restarted < 0.5


def test_a_threshold_is_found_by_scanning_and_held_in_the_local_fit(stand: StandConfig) -> None:
    # A seat that flips once the fibre has lain slack 30 ms: the output error is flat
    # between the recorded episodes' lengths, so a gradient cannot find the dwell; the
    # local fit leaves it where it started, the scan finds it.
    from sim.identify.fitting import fit, scan_thresholds

    effect = "fibre_pulley_jump"
    truth = {"step_m": 5e-4, "depth_scale_m": 1e-5, "dwell_s": 0.03}
    tr, _ = _trace(stand, 8.131, [EffectSpec(effect, truth)])
    nominal = stand.stand_params("final", 8.131)
    candidate = Candidate.build(effect)
    start = dict(BASE, **{f"{effect}.{k}": v for k, v in truth.items()})
    start[f"{effect}.onset_m"] = 0.0
    start[f"{effect}.seats"] = 0.0  # the truth's form: two grooves
    start[f"{effect}.dwell_s"] = 0.1  # longer than every episode: the seat never moves
    local = fit(candidate, [tr], nominal, baseline=start, single_start=True, max_nfev=5)
    assert local.values[f"{effect}.dwell_s"] == pytest.approx(0.1, rel=1e-9)
    scanned, cost, sims = scan_thresholds(candidate, [tr], nominal, start)
    assert sims > 20
    assert cost < 0.1 * local.train_cost
    # Any dwell between the longest episode shorter than 30 ms and the shortest longer
    # one explains the recording alike; the scan lands in that gap.
    assert 0.015 < scanned[f"{effect}.dwell_s"] < 0.045


def test_screening_on_top_of_a_pulley_jump_leaves_its_thresholds_and_count_alone(
    stand: StandConfig,
) -> None:
    # Screening on top of an accepted effect projects off the base fit's parameter
    # directions. A threshold or a count has none (the output steps): bumping the seat
    # count from 0 to 0.01 made a stand no one can build, and the diagnosis stopped there.
    from sim.identify.fitting import FitResult
    from sim.identify.screening import outputs_of, probe_values, screen

    effect = "fibre_pulley_jump"
    tr, _ = _trace(stand, 8.131, [EffectSpec(effect, {"step_m": 5e-4, "seats": 2.0})])
    nominal = stand.stand_params("final", 8.131)
    candidate = Candidate.build(effect)
    values = dict(BASE, **{p.name: 0.0 for p in candidate.params if p.name not in BASE})
    values.update({f"{effect}.step_m": 4e-4, f"{effect}.depth_scale_m": 1e-3})
    base = FitResult(candidate, values, 0.0, 0)
    scores, _, sims = screen([tr], nominal, base, outputs_of(candidate, values, [tr], nominal),
                             ["channel_time_skew", "stick_slip_friction"])  # fmt: skip
    scanned = sum(1 for p in candidate.params if p.scan)
    assert sims == len(candidate.params) - scanned + sum(
        len(probe_values(e, values)) for e in ("channel_time_skew", "stick_slip_friction")
    )
    assert all(0.0 <= s <= 1.0 for s in scores.values())


@pytest.mark.parametrize("effect", ["channel_time_skew", "fibre_viscoelastic"])
def test_screenings_probes_in_one_batch_give_each_probe_alone_bit_for_bit(
    stand: StandConfig, effect: str
) -> None:
    # The score test simulates an effect's probes as one batch per trace. A batch runs
    # every row as far as its most-ahead row reads (a skew's probes: early channels of
    # both signs), and no row may see another's.
    from sim.identify.screening import _stacks_of, probe_values

    tr, _ = _trace(stand, 3.096, [EffectSpec(effect, {})])
    nominal = stand.stand_params("final", 3.096)
    candidate = Candidate.build(effect)
    probes = probe_values(effect, dict(BASE))
    batch = _stacks_of(candidate, probes, [tr, tr], nominal)
    alone = np.stack([_stacks_of(candidate, [p], [tr, tr], nominal)[0] for p in probes])
    assert len(probes) >= 3
    assert np.array_equal(batch, alone)


@pytest.mark.parametrize(
    "params",
    [
        {"force_skew_s": 0.0, "displacement_skew_s": 0.006},  # the dial gauge 12 samples late
        {"force_skew_s": 0.008, "displacement_skew_s": 0.0},  # the load cell 16 samples late
        {"force_skew_s": -0.004, "displacement_skew_s": 0.010},  # the load cell early
        {"force_skew_s": 0.0, "displacement_skew_s": -0.004},
    ],
)
def test_a_skewed_channel_restarts_from_its_true_values_so_restarts_cost_nothing(
    stand: StandConfig, params: dict[str, float]
) -> None:
    # A channel recorded Δt late shows the true value of Δt earlier. A restart reads the
    # true state Δt later in the recording; the first-order u + Δt·v (v and the force
    # unshifted) missed by ½·a·Δt² in the light weight's bounces, and the true model,
    # restarted, predicted the force of a quick light-weight trace with an NRMSE of 0.9.
    # A channel recorded early reads past its run's end: each run goes on that far.
    # Restarted, the true model stays within a real recording's noise (0.2–1.0 units;
    # one run is exact: a clean recording's drive passes unfiltered).
    restarted, _ = _restarted_and_open_loop_errors(stand, "channel_time_skew", params)
    assert restarted < 1.5


@pytest.mark.parametrize(
    "params",
    [
        {"cutoff_hz": 20.0, "damping_ratio": 1.0},  # slower than the warm-up: 25× before
        {"cutoff_hz": 40.0, "damping_ratio": 0.2},  # a ringing load cell: 3.4× before
    ],
)
def test_a_slow_force_gauge_restarts_where_the_recording_shows_it(
    stand: StandConfig, params: dict[str, float]
) -> None:
    # The gauge filter's state is what the recording shows (the recorded force and its
    # rate), not settled on the model's force: a 20 Hz gauge had not caught up by the end
    # of the warm-up, and restarts cost 25× the open-loop error. In noise units of a real
    # recording: 0.33 and 1.28 (the gauge's own state is the local fit's, not refined;
    # the ringing cell's was 1.62 before the starts were refined over their warm-ups).
    restarted, _ = _restarted_and_open_loop_errors(stand, "force_gauge_dynamics", params)
    assert restarted < 1.5


def test_a_segment_holds_the_pulley_seat_where_the_recorded_slack_put_it(
    stand: StandConfig,
) -> None:
    # A taut fibre throughout (the heavy weight, slowly): the model's own slack never
    # moves the seat. Given the seat the recorded episodes read (a step of 0.4 mm at
    # one sample mid-segment), the run holds it there: nothing changes before that
    # sample, and the fibre's tension jumps by about k·step right after it.
    params = stand.stand_params("final", 8.131)
    _, x = plan_motion(SLOW, stand.drive).sample(stand.sample_rate_hz)
    rel = np.ascontiguousarray(x - x[0])
    step, at = 4e-4, 1200
    row = parameter_row(params, [EffectSpec("fibre_pulley_jump", {"step_m": step})])[None, :]
    starts = np.array([0, 800], dtype=np.int64)
    lengths = np.array([800, rel.size - 800], dtype=np.int64)
    init = np.zeros((1, 2, layout.N_INIT))
    run = Model(params).run(x, stand.sample_rate_hz)
    assert run.force_n.min() > 0.3 * params.preload_tension_n  # never slack
    init[0, 1, layout.I_U], init[0, 1, layout.I_V] = run.u_m[800], run.v_m_s[800]
    init[0, 1, layout.I_F] = run.force_n[800]
    knots, coef = friction_arrays(params.friction)
    seat = np.zeros((1, rel.size))
    seat[0, at:] = step
    width = int(lengths.max())
    outs = []
    for seats in (np.zeros((1, 0)), np.zeros((1, rel.size)), seat):
        u, f = np.empty((1, 2, width)), np.empty((1, 2, width))
        compose.union().simulate_segments_serial(
            rel, 1.0 / stand.sample_rate_hz, 1, row, knots, coef, starts, lengths, init, u, f,
            seats,
        )  # fmt: skip
        outs.append(f[0, 1])
    model_own, at_rest, stepped = outs
    np.testing.assert_array_equal(model_own, at_rest)  # never slack: the seat stayed
    k = at - starts[1]
    np.testing.assert_array_equal(stepped[: k - 1], at_rest[: k - 1])
    jump = stepped[k] - at_rest[k]
    assert jump == pytest.approx(params.stiffness_n_m * step, rel=0.3)


def test_the_maxwell_branch_restarts_with_the_force_it_had_when_the_fibre_went_slack(
    stand: StandConfig,
) -> None:
    # A quick unloading takes the fibre's tension law (k·δ + c·δ̇ + q) to zero while its
    # elongation δ is still positive: the model's fibre goes slack there and the branch
    # relaxes. A branch history that followed δ alone until δ < 0 restarted every segment
    # after slack with the wrong branch force: 3.9× the open-loop error, about 6.6 noise
    # units of a real recording (0.01 now).
    params = {"branch_stiffness_n_m": 2.0e4, "relaxation_time_s": 0.03}
    restarted, _ = _restarted_and_open_loop_errors(stand, "fibre_viscoelastic", params)
    assert restarted < 0.5


@pytest.mark.parametrize("tau_s", [0.003, 0.03, 0.3])
def test_restarts_from_the_true_states_give_the_maxwell_branch_its_open_loop_force(
    stand: StandConfig, tau_s: float
) -> None:
    # The drive pulls out 4 mm in 20 ms (0.2 m/s: the fibre goes slack while δ > 0),
    # holds, and takes the fibre up again. Restarted from the true u and v, the branch's
    # history must give the force the open-loop run has: the branch force it restarts
    # with is the only state not measured. Judged on δ alone, as a step per sample, and
    # switched at whole samples, restarts missed by 0.3, 4.3 and 8.1 N (τ 3, 30, 300 ms).
    from tests.fixtures.physics.make_reference import RATE, drive

    params = stand.stand_params("final", 8.131)
    x = drive()
    model = Model(params, [EffectSpec("fibre_viscoelastic", {"relaxation_time_s": tau_s})])
    run = model.run(x, RATE)
    starts = np.array([0, 100, 200, 300], dtype=np.int64)
    lengths = np.array([130, 130, 130, 100], dtype=np.int64)
    restarts = Restarts(starts, lengths, run.u_m, run.v_m_s, run.force_n)
    _, f = model.run_segments(x, RATE, restarts)
    for k, (s, n) in enumerate(zip(starts, lengths, strict=True)):
        np.testing.assert_allclose(f[0, k, :n], run.force_n[s : s + n], atol=0.01)
