"""The other truth stand (sim/checks/otherstand): physics, effects' limits, independence, wiring."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from drivers.limits import DriveLimits
from drivers.signals import Shape, SignalSpec, plan_motion
from labstand.cli import main
from sim.checks.check import FULL_CAMPAIGN, make_campaign, recording_set
from sim.checks.otherstand import OTHER_EFFECTS, OTHER_PAIRS, simulate
from sim.checks.otherstand import _kernel as kern
from sim.checks.otherstand.campaign import OTHER_SETS, OTHER_SMALL, make_other_campaign
from sim.checks.otherstand.gauges import sample_delayed
from sim.checks.otherstand.stand import parameter_row
from sim.config import StandConfig
from sim.params import StandParams

RATE = 2000.0
LIGHT, HEAVY = 3.096, 8.131
PHYSICAL = [n for n, e in OTHER_EFFECTS.items() if e.kind == "physical"]


def _x(shape: Shape, a: float, f: float, cycles: int, ramp: float = 0.25) -> np.ndarray:
    spec = SignalSpec(shape, a, f, cycles=cycles, ramp_fraction=ramp, dwell_end_s=0.5)
    return plan_motion(spec, DriveLimits()).sample(RATE)[1]


@pytest.fixture(scope="module")
def heavy(stand: StandConfig) -> StandParams:
    return stand.stand_params("final", HEAVY)


@pytest.fixture(scope="module")
def slow() -> np.ndarray:
    return _x(Shape.QUASI_SINUSOIDAL, 0.070, 0.4, 1)


@pytest.fixture(scope="module")
def burst() -> np.ndarray:
    return _x(Shape.TRAPEZOIDAL, 0.030, 1.0, 2, 0.2)


def test_static_rest_stays_at_rest_with_every_effect(heavy: StandParams) -> None:
    x = np.zeros(2001)
    zero = {name: dict(e.zero) for name, e in OTHER_EFFECTS.items()}
    run = simulate(heavy, zero, x, RATE)
    assert np.max(np.abs(run.u_m)) < 1e-12
    assert np.max(np.abs(run.force_n - heavy.preload_tension_n)) < 1e-9
    # Drawn (non-zero) physical effects, all at once: still at rest, at the preload.
    rng = np.random.default_rng(3)
    drawn = {name: OTHER_EFFECTS[name].draw(rng) for name in PHYSICAL}
    run = simulate(heavy, drawn, x, RATE)
    assert np.max(np.abs(run.true_u_m)) < 1e-9
    assert np.max(np.abs(run.true_force_n - heavy.preload_tension_n)) < 1e-6


@pytest.mark.parametrize("mass", [LIGHT, HEAVY])
def test_effects_off_agrees_with_the_baseline_model(stand: StandConfig, mass: float) -> None:
    # The one place that compares with the candidate code: the §2 baseline.
    from sim.model import Model

    params = stand.stand_params("final", mass)
    for x in (
        _x(Shape.QUASI_SINUSOIDAL, 0.070, 0.4, 1),
        _x(Shape.TRAPEZOIDAL, 0.010, 2.0, 3),  # quick; the light weight goes slack
    ):
        ours = simulate(params, {}, x, RATE)
        theirs = Model(params).run(x, RATE)
        assert np.max(np.abs(ours.force_n - theirs.force_n)) < 0.1  # N, of tens of N
        assert np.max(np.abs(ours.u_m - theirs.u_m)) < 5e-6
    assert np.mean(ours.true_force_n <= 0) > (0.05 if mass == LIGHT else 0.0)


def test_maxwell_branches_follow_the_strain_rate_taut_and_relax_slack(heavy: StandParams) -> None:
    p, arest = parameter_row(heavy, {"fibre_viscoelastic": OTHER_EFFECTS["fibre_viscoelastic"]
                                     .params({"fast_ratio": 0.5, "slow_ratio": 0.2})})  # fmt: skip
    tab_x, tab_c = np.array([0.0, 1.0]), np.zeros((4, 1))
    y = np.zeros(kern.N_STATE)
    y[kern.S_Q : kern.S_Q + 2] = (10.0, 4.0)
    dy, tens = np.empty(kern.N_STATE), np.empty(2)
    slack = np.array([False, False])
    kern.rhs(y, -0.01, 0.2, p, tab_x, tab_c, arest, slack, 0.0, dy, tens)
    assert tens[0] == 0.0
    assert dy[kern.S_Q] == pytest.approx(-10.0 / p[kern.P_TAUA])
    assert dy[kern.S_Q + 1] == pytest.approx(-4.0 / p[kern.P_TAUB])
    taut = np.array([True, True])
    kern.rhs(y, 0.0, 0.2, p, tab_x, tab_c, arest, taut, 0.0, dy, tens)
    assert dy[kern.S_Q] == pytest.approx(p[kern.P_KA] * 0.2 - 10.0 / p[kern.P_TAUA])
    assert tens[0] == pytest.approx(heavy.preload_tension_n + heavy.damping_n_s_m * 0.2 + 14.0)


def test_viscoelastic_changes_quick_events_far_more_than_slow_motion(
    heavy: StandParams, slow: np.ndarray, burst: np.ndarray
) -> None:
    ve = {"fibre_viscoelastic": {"fast_ratio": 0.5, "fast_tau_s": 0.01, "slow_ratio": 0.0}}

    def change(x: np.ndarray) -> float:
        d = simulate(heavy, ve, x, RATE).force_n - simulate(heavy, {}, x, RATE).force_n
        return float(np.sqrt(np.mean(d**2)))

    # The slow motion feels it only at the reversals (where the weight sticks while the
    # drive turns); the snatches of the burst, many times more.
    assert change(slow) < 0.1 * change(burst)
    assert change(burst) > 5.0  # N rms


def test_skew_moves_the_cross_correlation_peak_by_the_delay(
    heavy: StandParams, burst: np.ndarray
) -> None:
    delay = 10.25 / RATE  # a buffering offset of 10 samples plus a fraction
    base = simulate(heavy, {}, burst, RATE)
    skewed = simulate(heavy, {"channel_time_skew": {"force_delay_s": delay}}, burst, RATE)
    a = base.force_n - base.force_n.mean()
    b = skewed.force_n - skewed.force_n.mean()
    lags = np.arange(-40, 41)
    xc = [np.dot(a[40:-40], b[40 + k : b.size - 40 + k]) for k in lags]
    assert lags[int(np.argmax(xc))] == 10
    assert np.array_equal(skewed.u_m, base.u_m)  # the other channel untouched
    # The fraction is honoured: a smooth signal delayed by 2.3 samples, early by 7.6.
    t = np.arange(4001) / (4 * RATE)
    s = np.sin(2 * math.pi * 13.0 * t)
    for d in (2.3 / RATE, -7.6 / RATE):
        got = sample_delayed(s, 4, d, RATE)
        ti = np.arange(got.size) / RATE
        inside = (ti > 0.02) & (ti < ti[-1] - 0.02)
        want = np.sin(2 * math.pi * 13.0 * (ti - d))
        assert np.max(np.abs(got - want)[inside]) < 1e-5


def test_dial_gauge_gain_scales_u_and_backlash_holds_at_reversals(
    heavy: StandParams, slow: np.ndarray
) -> None:
    base = simulate(heavy, {}, slow, RATE)
    gained = simulate(heavy, {"dial_gauge_calibration": {"gain": 1.1}}, slow, RATE)
    assert np.allclose(gained.u_m, 1.1 * base.u_m, atol=1e-12, rtol=0)
    assert np.array_equal(gained.force_n, base.force_n)
    play = 2e-5
    lash = simulate(heavy, {"dial_gauge_calibration": {"backlash_m": play}}, slow, RATE)
    err = lash.u_m - base.u_m
    assert np.max(np.abs(err)) <= play / 2 + 1e-12
    assert np.max(np.abs(err)) > 0.9 * play / 2  # the play is taken up during the motion
    top = int(np.argmax(base.u_m))  # at the reversal the reading holds while u turns back
    after = slice(top, top + 200)
    assert np.ptp(lash.u_m[after]) < np.ptp(base.u_m[after])


def test_force_gauge_keeps_static_gain_and_attenuates_snatches(
    heavy: StandParams, burst: np.ndarray
) -> None:
    gauge = {"amplifier_cutoff_hz": 30.0, "cell_frequency_hz": 300.0, "cell_damping": 0.05}
    base = simulate(heavy, {}, burst, RATE)
    run = simulate(heavy, {"force_gauge_dynamics": gauge}, burst, RATE)
    assert run.force_n[-1] == pytest.approx(base.force_n[-1], abs=0.05)  # settled at the end
    assert run.force_n.max() < 0.99 * base.force_n.max()
    a, b = base.force_n - base.force_n.mean(), run.force_n - run.force_n.mean()
    lags = np.arange(0, 30)
    lag = lags[int(np.argmax([np.dot(a[: a.size - k], b[k:]) for k in lags]))]
    assert 5 <= lag <= 15  # samples: the 30 Hz amplifier's ~5 ms delay
    assert np.array_equal(run.u_m, base.u_m)


def test_pulley_friction_makes_hysteresis_of_its_kinetic_level(
    heavy: StandParams, slow: np.ndarray
) -> None:
    pulley = {"inertia_kg_m2": 1e-4, "kinetic_torque_n_m": 0.02, "breakaway_ratio": 0.5}
    run = simulate(heavy, {"pulley_inertia_friction": pulley}, slow, RATE)
    diff = run.true_force_n - run.weight_force_n  # T₁ − T₂ = the bearing's rim force
    xd = np.gradient(slow) * RATE
    kinetic = 0.02 / heavy.pulley_radius_m
    pulling, returning = xd > 0.03, xd < -0.03
    assert np.median(diff[pulling]) == pytest.approx(kinetic, rel=0.15)
    assert np.median(diff[returning]) == pytest.approx(-kinetic, rel=0.15)
    assert np.max(np.abs(diff)) < 1.5 * kinetic + 1.0  # never beyond breakaway plus inertia


def test_stick_slip_holds_until_the_static_level(heavy: StandParams) -> None:
    # A slow pull from rest: the weight breaks away when n·ΔT exceeds the static friction.
    t = np.arange(int(1.5 * RATE)) / RATE
    x = 0.002 * np.clip(t - 0.2, 0.0, None)  # 2 mm/s
    excess = 0.8
    ss = {"stick_slip_friction": {"static_excess": excess, "stribeck_speed_m_s": 0.005}}
    run = simulate(heavy, ss, x, RATE)
    moving = np.flatnonzero(np.gradient(run.true_u_m) * RATE > 1e-3)
    assert moving.size > 0
    pull = heavy.projection * (run.true_force_n[moving[0]] - heavy.preload_tension_n)
    kinetic = heavy.normal_force_n * 0.066  # μ at the table's lowest speed
    assert pull == pytest.approx((1 + excess) * kinetic, rel=0.1)
    base = simulate(heavy, {}, x, RATE)  # the regularised baseline creeps from the start
    before = int(0.3 * RATE)  # the drive has pulled 0.2 mm, short of the breakaway
    assert base.true_u_m[before] > 20e-6
    assert abs(run.true_u_m[before]) < 1e-7


def test_side_load_grows_faster_than_tension_and_vanishes_when_slack(
    heavy: StandParams,
) -> None:
    tab = heavy.friction
    assert tab is not None
    pchip = tab.pchip()
    tab_x, tab_c = np.asarray(pchip.x), np.ascontiguousarray(pchip.c)
    forces = []
    for tension_extra in (0.0, 50.0, 150.0):
        accs = []
        for on in (0.0, 0.2):
            sl = {"side_load_friction": {"wall_mu": on, "exponent": 1.6}}
            p, arest = parameter_row(heavy, sl)
            y = np.zeros(kern.N_STATE)
            y[kern.S_V] = 0.05  # sliding up
            dy, tens = np.empty(kern.N_STATE), np.empty(2)
            x = tension_extra / heavy.stiffness_n_m
            kern.rhs(y, x, 0.05 * heavy.projection, p, tab_x, tab_c, arest,
                     np.array([True, True]), 0.0, dy, tens)  # fmt: skip
            accs.append(dy[kern.S_V])
        forces.append((tens[1], heavy.mass_kg * (accs[0] - accs[1])))
    (t0, f0), (t1, f1), (t2, f2) = forces
    sin_b = heavy.lateral_offset_m / heavy.free_length_m
    assert f1 == pytest.approx(0.2 * sin_b * t1 * (t1 / 50.0) ** 0.6, rel=1e-9)
    assert f2 / t2 > f1 / t1 > f0 / t0  # per newton of tension, more at higher tension
    p, arest = parameter_row(heavy, {"side_load_friction": {"wall_mu": 0.2, "exponent": 1.6}})
    y = np.zeros(kern.N_STATE)
    y[kern.S_V] = 0.05
    dy, tens = np.empty(kern.N_STATE), np.empty(2)
    kern.rhs(y, -0.01, 0.0, p, tab_x, tab_c, arest, np.array([False, False]), 0.0, dy, tens)
    kinetic = heavy.normal_force_n * float(tab.mu_at(np.array([0.05]))[0])
    assert dy[kern.S_V] == pytest.approx((-heavy.gravity_along_n - kinetic) / heavy.mass_kg)


def test_seat_ratchets_only_after_deep_slack(
    heavy: StandParams, slow: np.ndarray, burst: np.ndarray
) -> None:
    jump = {"step_m": 4e-4, "threshold_m": 5e-4, "tau_s": 0.005, "seats": 3.0}
    quiet = simulate(heavy, {"fibre_pulley_jump": jump}, slow, RATE)
    assert np.all(quiet.seat_m == 0.0)  # taut all along: no seat change
    run = simulate(heavy, {"fibre_pulley_jump": jump}, burst, RATE)
    final = run.seat_m[-1]
    assert final == pytest.approx(8e-4, abs=1e-8)  # two steps: the flange stops the third
    assert np.all(np.diff(run.seat_m) >= -1e-15)  # it only ever walks one way


def test_two_string_spans_ring_after_snatches_but_not_in_slow_motion(
    heavy: StandParams, slow: np.ndarray, burst: np.ndarray
) -> None:
    tv = {"fibre_transverse_vibration": OTHER_EFFECTS["fibre_transverse_vibration"].params(
        {"loss_factor": 0.02, "load_scale": 1.0})}  # fmt: skip
    d_slow = simulate(heavy, tv, slow, RATE).force_n - simulate(heavy, {}, slow, RATE).force_n
    assert np.max(np.abs(d_slow)) < 0.05
    high = butter(4, 150.0 / (RATE / 2), "high", output="sos")  # above the weight's motion

    def ripple(effects: dict[str, dict[str, float]]) -> float:
        return float(np.std(sosfiltfilt(high, simulate(heavy, effects, burst, RATE).force_n)))

    assert ripple(tv) > 1.5 * ripple({})


def test_the_package_imports_none_of_the_candidate_code() -> None:
    import sim.params

    sim_dir = Path(sim.params.__file__).parent
    # sim/__init__ re-exports the model, so the package is stubbed: what is imported is
    # what sim.checks.otherstand itself pulls in.
    code = (
        "import sys, importlib.util as iu, numpy as np\n"
        f"spec = iu.spec_from_file_location('sim', {str(sim_dir / '__init__.py')!r},\n"
        f"    submodule_search_locations=[{str(sim_dir)!r}])\n"
        "sys.modules['sim'] = iu.module_from_spec(spec)  # not executed\n"
        "from sim.config import default_config\n"
        "import sim.checks.otherstand, sim.checks.otherstand.campaign\n"
        "st = default_config().stand_params('final', 3.096)\n"
        "sim.checks.otherstand.simulate(st, {'fibre_viscoelastic': {}}, np.zeros(50), 2000.0)\n"
        "bad = ('sim.effects', 'sim.model', 'sim.physics', 'sim.identify')\n"
        "print(sorted(m for m in sys.modules if m.startswith(bad)))\n"
        "print('sim.checks.otherstand.stand' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120)  # fmt: skip
    assert out.stdout.split() == ["[]", "True"]


def test_draws_stay_in_their_ranges_and_every_pair_composes(heavy: StandParams) -> None:
    rng = np.random.default_rng(0)
    for _ in range(20):
        skew = OTHER_EFFECTS["channel_time_skew"].draw(rng)
        assert all(abs(v) <= 0.0255 for v in skew.values())
        gain = OTHER_EFFECTS["dial_gauge_calibration"].draw(rng)["gain"]
        assert 0.88 <= gain <= 1.12
        assert abs(gain - 1) >= 0.01
    for effect in OTHER_EFFECTS.values():
        assert "why" not in effect.why.lower() or effect.why  # every effect says why
        assert len(effect.why) > 100
    x = np.zeros(200)
    for a, b in OTHER_PAIRS:
        run = simulate(heavy, {a: OTHER_EFFECTS[a].draw(rng), b: OTHER_EFFECTS[b].draw(rng)},
                       x, RATE)  # fmt: skip
        assert np.all(np.isfinite(run.force_n))
    with pytest.raises(ValueError, match="unknown effect"):
        simulate(heavy, {"fibre_wobble": {}}, x, RATE)
    with pytest.raises(ValueError, match="unknown parameter"):
        simulate(heavy, {"fibre_viscoelastic": {"branch_stiffness_n_m": 1.0}}, x, RATE)


def test_other_campaigns_reach_the_check_as_traces(stand: StandConfig) -> None:
    rng = np.random.default_rng(2)
    traces, oracle, params = make_campaign(
        stand, "fibre_pulley_jump+dial_gauge_calibration", LIGHT, rng,
        truth_stand="other", other_campaign=OTHER_SMALL,
    )  # fmt: skip
    assert [t.name for t in traces] == ["burst", "slow"]
    assert {k.split(".")[0] for k in params} == {"fibre_pulley_jump", "dial_gauge_calibration"}
    for trace, out in zip(traces, oracle, strict=True):
        assert trace.u_m.shape == out.u_m.shape
        rest = slice(0, 800)
        # noise as the validation set's: 0.3 N rms + 0.2 N hum; 5 µm on the dial gauge
        assert 0.3 < float(np.std(trace.force_n[rest])) < 0.4
        assert 3e-6 < float(np.std(trace.u_m[rest])) < 8e-6
        resid = trace.u_m[trace.present] - out.u_m[trace.present]
        assert float(np.std(resid)) < 1e-5  # the oracle is the noise-free recording


@pytest.mark.parametrize("mass", [LIGHT, HEAVY])
def test_the_recording_sets_are_what_they_say(stand: StandConfig, mass: float) -> None:
    # The gentle set never slackens the fibre; the brisk one slackens it in three of its
    # four recordings, more than the validation set's does.
    def slack_shares(name: str) -> list[float]:
        camp = make_other_campaign(
            stand.stand_params("final", mass), [], np.random.default_rng(3), OTHER_SETS[name]
        )
        return [float(np.mean(f < 0.5)) for f in camp.truth_f]

    assert max(slack_shares("gentle")) == 0.0
    brisk, moderate = slack_shares("brisk"), slack_shares("moderate")
    assert sum(share > 0.1 for share in brisk) == 3
    assert np.mean(brisk) > 2 * np.mean(moderate)


def test_cli_refuses_pairs_without_the_other_truth(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["diagnose-check", "--pairs", "--effects"]) == 2
    assert "--pairs needs --truth other" in capsys.readouterr().err
    bad = ["diagnose-check", "--truth", "other", "--effects", "--pairs", "a+b"]
    assert main(bad) == 2
    assert "two different effects" in capsys.readouterr().err


def test_cli_writes_the_truth_into_its_json(tmp_path: Path) -> None:
    out = tmp_path / "check.json"
    # No campaigns at all: the report still names its truth (the real run takes minutes).
    assert main(["diagnose-check", "--truth", "other", "--effects", "-o", str(out)]) == 0
    assert json.loads(out.read_text())["truth"] == "other"
    assert json.loads(out.read_text())["recordings"] == "moderate"
    args = ["diagnose-check", "--truth", "other", "--recordings", "brisk", "--effects"]
    assert main([*args, "-o", str(out), "--force"]) == 0  # (without: refused, exists)
    assert json.loads(out.read_text())["recordings"] == "brisk"


def test_cli_refuses_a_recording_set_it_cannot_use(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # Either truth records any set (the same drive signals for both); the paper-like
    # recordings of the first checks are one of them.
    out = tmp_path / "check.json"
    assert main(["diagnose-check", "--recordings", "paper", "--effects", "-o", str(out)]) == 0
    assert json.loads(out.read_text())["recordings"] == "paper"
    with pytest.raises(SystemExit):  # argparse's own refusal, exit 2
        main(["diagnose-check", "--recordings", "faster", "--effects"])
    assert "invalid choice" in capsys.readouterr().err
    both = ["diagnose-check", "--truth", "other", "--recordings", "gentle", "--small"]
    assert main([*both, "--effects"]) == 2
    assert "give one" in capsys.readouterr().err


def test_both_truths_record_the_same_drive_signals(stand: StandConfig) -> None:
    # The same-form truth on the validation campaigns' four recordings: the drive is the
    # other stand's, signal and limits alike (the rectangle at 0.3 m/s and 3 m/s²).
    moderate = recording_set("moderate", stand)
    assert moderate == OTHER_SETS["moderate"]
    traces, _, _ = make_campaign(stand, "none", HEAVY, np.random.default_rng(2), moderate)
    assert [t.name for t in traces] == [r.name for r in moderate]
    for trace, rec in zip(traces, moderate, strict=True):
        _, x = plan_motion(rec.signal, rec.limits).sample(stand.sample_rate_hz)
        assert trace.x_m.size == x.size
        assert np.max(np.abs(trace.x_m - x)) < 1e-5  # the drive encoder's noise, 1 µm rms
    paper = recording_set("paper", stand)
    assert [(r.name, r.signal) for r in paper] == list(FULL_CAMPAIGN)
    assert all(r.limits == stand.drive for r in paper)
    with pytest.raises(ValueError, match="unknown recording set"):
        recording_set("faster", stand)
