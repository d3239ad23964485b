"""The baseline model checked against physics: balances, limits, regimes, the reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import StandConfig
from sim.model import Model, SimulationError
from sim.modes import linear_modes
from sim.params import StandParams
from sim.reference import solve_reference
from sim.sensitivity import nearby_run_divergence
from sim.situations import SITUATIONS

RATE = 2000.0


def _nrmse(sim: np.ndarray, ref: np.ndarray) -> float:
    return float(np.linalg.norm(sim - ref) / np.linalg.norm(ref - ref.mean()))


def _situation_run(stand: StandConfig, name: str, params: str = "final"):
    s = SITUATIONS[name]
    _, x = plan_motion(s.signal, stand.drive).sample(RATE)
    return x, stand.stand_params(params, s.mass_kg)


@pytest.mark.parametrize("params", ["starting", "final"])
@pytest.mark.parametrize("mass_kg", [3.096, 8.131])
def test_static_rest_stays_at_rest(stand: StandConfig, params: str, mass_kg: float) -> None:
    p = stand.stand_params(params, mass_kg)
    run = Model(p).run(np.zeros(20_000), RATE)
    assert np.abs(run.u_m).max() < 1e-12
    assert np.allclose(run.force_n, p.preload_tension_n, rtol=1e-12)
    # T₀ = m·g·sin α / n, by hand for the default geometry:
    n = math.sqrt(1 - (0.280 / 0.640) ** 2)
    assert p.preload_tension_n == pytest.approx(mass_kg * 9.81 * math.sin(math.radians(30.6)) / n)


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_force_balance_while_sliding_steadily(stand: StandConfig, direction: float) -> None:
    p = stand.stand_params("final", 8.131)
    drive_speed = 0.02  # m/s, a slow constant pull (or release)
    t = np.arange(int(8 * RATE)) / RATE
    x = direction * drive_speed * t
    run = Model(p).run(x, RATE)
    steady = t > 6.0  # the 9 Hz ringing from the start has decayed (τ ≈ 0.7 s)
    v = direction * drive_speed / p.projection
    # A whole number of ringing periods averages the last of the 9 Hz ringing away.
    assert run.v_m_s[steady].mean() == pytest.approx(v, rel=1e-3)
    assert np.abs(run.v_m_s[steady] - v).max() < 0.02 * abs(v)
    friction = float(p.friction.force_n(np.array([v]), p.normal_force_n)[0])  # type: ignore[union-attr]
    expected = (p.gravity_along_n + friction) / p.projection
    assert run.force_n[steady].mean() == pytest.approx(expected, rel=1e-3)
    # …and the fibre is stretched accordingly: δ = T/k + c·δ̇/k with δ̇ = 0 at steady state.
    assert direction * friction > 0  # friction opposes the sliding direction


@pytest.mark.parametrize("name", list(SITUATIONS))
@pytest.mark.parametrize("params", ["starting", "final"])
def test_tension_is_never_negative(stand: StandConfig, name: str, params: str) -> None:
    x, p = _situation_run(stand, name, params)
    run = Model(p).run(x, RATE)
    assert run.force_n.min() >= 0.0
    assert np.all(np.isfinite(run.u_m))


@pytest.mark.parametrize(
    ("name", "slack_expected"), [("10", True), ("11", True), ("12a", False), ("14", False)]
)
def test_slack_in_quick_heavy_situations_only(
    stand: StandConfig, name: str, slack_expected: bool
) -> None:
    x, p = _situation_run(stand, name)
    run = Model(p).run(x, RATE)
    assert bool(run.slack.any()) is slack_expected
    if slack_expected:
        # Briefly: the weight stays on the stand, within 1.5× the stroke.
        assert run.slack.mean() < 0.25
        amplitude = SITUATIONS[name].signal.amplitude_m
        assert run.u_m.max() < 1.5 * amplitude


@pytest.mark.parametrize("name", list(SITUATIONS))
def test_agrees_with_the_reference_solution_within_0_1_percent(
    stand: StandConfig, name: str
) -> None:
    s = SITUATIONS[name]
    spec = s.signal
    if s.rate_class == "slower":  # slow runs are smooth and long: one cycle shows enough
        spec = SignalSpec(spec.shape, spec.amplitude_m, spec.frequency_hz, cycles=1)
    _, x = plan_motion(spec, stand.drive).sample(RATE)
    p = stand.stand_params("final", s.mass_kg)
    ref = solve_reference(x, RATE, p, method="DOP853", rtol=1e-10, atol=1e-13)
    run = Model(p).run(x, RATE)
    assert _nrmse(run.u_m, ref.u_m) < 1e-3
    assert _nrmse(run.force_n, ref.force_n) < 1e-3


def test_the_slack_to_taut_jump_does_not_cost_the_integrator_its_order(stand: StandConfig) -> None:
    x, p = _situation_run(stand, "10")
    assert Model(p).run(x, RATE).slack.any()
    truth = Model(p, substeps=64).run(x, RATE).force_n
    errors = [_nrmse(Model(p, substeps=k).run(x, RATE).force_n, truth) for k in (2, 4)]
    # Fourth order: halving the step divides the error by ≈ 16 (first order would give 2).
    assert errors[0] / errors[1] > 8


def test_linearised_mode_matches_the_hand_calculation_and_the_paper(stand: StandConfig) -> None:
    n2 = 1 - (0.280 / 0.640) ** 2
    for mass, paper_hz in ((3.096, 25.0), (8.131, 15.25)):
        (mode,) = linear_modes(stand.stand_params("starting", mass))
        by_hand = math.sqrt(n2 * 94e3 / mass) / (2 * math.pi)
        assert mode.frequency_hz == pytest.approx(by_hand, rel=1e-12)
        assert mode.frequency_hz == pytest.approx(paper_hz, rel=0.015)


def test_free_ringing_in_the_simulation_has_the_linearised_frequency(stand: StandConfig) -> None:
    p = stand.stand_params("starting", 3.096)  # no friction: a clean linear oscillator
    (mode,) = linear_modes(p)
    # A small, quick 0.1 mm drive step rings the weight without slackening the fibre.
    x = np.zeros(int(4 * RATE))
    x[100:] = 1e-4
    run = Model(p).run(x, RATE)
    assert not run.slack.any()
    signal = run.u_m[200:] - run.u_m[-1]
    spectrum = np.abs(np.fft.rfft(signal * np.hanning(signal.size), n=1 << 18))
    peak_hz = np.fft.rfftfreq(1 << 18, 1 / RATE)[np.argmax(spectrum)]
    assert peak_hz == pytest.approx(mode.damped_frequency_hz, rel=5e-3)


def test_batch_and_stream_equal_single_runs(stand: StandConfig) -> None:
    x, p = _situation_run(stand, "11")
    sets = [
        {"stiffness_n_m": k, "damping_n_s_m": c}
        for k, c in ((30e3, 20.0), (34e3, 27.5), (40e3, 35.0))
    ]
    batch = Model(p).run_batch(x, RATE, sets)
    for i, q in enumerate(sets):
        single = Model(p.with_(**q)).run(x, RATE)
        assert np.array_equal(batch.u_m[i], single.u_m)
        assert np.array_equal(batch.force_n[i], single.force_n)
    stream = Model(p).stream(RATE, x0_m=float(x[0]))
    parts = [stream.advance(x[i : i + 97]) for i in range(1, x.size, 97)]
    single = Model(p).run(x, RATE)
    assert np.array_equal(np.concatenate([u for u, _ in parts]), single.u_m[1:])
    assert np.array_equal(np.concatenate([f for _, f in parts]), single.force_n[1:])


def test_violent_runs_amplify_tiny_differences_and_paper_runs_do_not(stand: StandConfig) -> None:
    x, p = _situation_run(stand, "11")
    first_cycle_end = 0.5 + 1 / 2.0
    calm = nearby_run_divergence(x, RATE, p, first_cycle_end)
    violent_spec = SignalSpec(Shape.TRAPEZOIDAL, 0.06, 2.0, cycles=5, ramp_fraction=0.25)
    _, xv = plan_motion(violent_spec, stand.drive).sample(RATE)
    violent = nearby_run_divergence(xv, RATE, p, first_cycle_end)
    assert calm.amplification < 3
    assert violent.amplification > 10


@pytest.mark.parametrize(
    ("x", "rate", "message"),
    [
        (np.array([0.0]), RATE, "≥ 2 samples"),
        (np.array([0.0, np.nan, 0.0]), RATE, "must be finite"),
        (np.zeros(10), 0.0, "sample rate must be > 0 Hz"),
    ],
)
def test_unusable_input_is_refused(x: np.ndarray, rate: float, message: str) -> None:
    p = StandParams(mass_kg=8.131, stiffness_n_m=34e3, damping_n_s_m=27.5)
    with pytest.raises(SimulationError, match=message):
        Model(p).run(x, rate)
