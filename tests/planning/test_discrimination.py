"""The separation as the diagnosis measures it: on its multiple-shooting segments."""

from __future__ import annotations

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import default_config
from sim.discrimination import (
    effect_steps,
    recording_of,
    residual_separation,
    shooting_separation,
)
from sim.effects import EffectSpec
from sim.effects.registry import EFFECTS
from sim.model import Model

NOISE_U, NOISE_F = 5e-6, 0.1
SKEW = EffectSpec("channel_time_skew", {"force_skew_s": 0.001})
GAUGE = EffectSpec("force_gauge_dynamics", {"cutoff_hz": 222.0, "damping_ratio": 0.71})


def _motion(shape: Shape, amplitude_mm: float, frequency_hz: float, mass: float) -> tuple:
    config = default_config()
    spec = SignalSpec(shape, amplitude_mm / 1e3, frequency_hz, 4, 0.1, 0.5, 1.0)
    x = plan_motion(spec, config.drive).sample(config.sample_rate_hz)[1]
    return x, config.stand_params("final", mass), config.sample_rate_hz


def _recorded(stand, effects, x, rate, noisy=False):  # type: ignore[no-untyped-def]
    run = Model(stand, effects).run(x, rate)
    noise = (NOISE_U, NOISE_F) if noisy else (0.0, 0.0)
    return recording_of("truth", x, run.u_m, run.force_n, rate, stand.mass_kg, noise)


def test_the_residual_counts_only_what_a_refit_would_not_absorb() -> None:
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(400, 3))
    assert residual_separation(np.zeros(400), directions) == 0.0
    along = directions @ np.array([2.0, -1.0, 0.5])
    assert residual_separation(along, directions) == pytest.approx(0.0, abs=1e-9)
    across = rng.normal(size=400)
    across -= directions @ np.linalg.lstsq(directions, across, rcond=None)[0]
    expected = np.sqrt(2.0 * np.mean(across**2))
    assert residual_separation(across + along, directions) == pytest.approx(expected)
    assert residual_separation(across, np.zeros((400, 0))) == pytest.approx(expected)


def test_chaos_after_a_snatch_is_not_a_separation() -> None:
    # The light weight thrown by a quick rectangle: the fibre goes slack every cycle.
    x, stand, rate = _motion(Shape.RECTANGULAR, 25.0, 2.0, 3.096)
    maxwell = (EffectSpec("fibre_viscoelastic", {"relaxation_time_s": 0.02}),)
    nearly = (EffectSpec("fibre_viscoelastic", {"relaxation_time_s": 0.02002}),)
    truth = _recorded(stand, maxwell, x, rate)
    assert truth.segments.count > 4  # cut after slack, as the diagnosis cuts it
    # open loop, a branch relaxing 0.1 % slower ends far from the truth after the snatches
    other = Model(stand, nearly).run(x, rate)
    mine = Model(stand, maxwell).run(x, rate)
    open_loop = np.sqrt(
        np.mean(((other.u_m - mine.u_m) / NOISE_U) ** 2)
        + np.mean(((other.force_n - mine.force_n) / NOISE_F) ** 2)
    )
    assert open_loop > 100.0
    # restarted from the measured states (and refitted) it misses by a sliver of the noise
    assert shooting_separation(truth, stand, maxwell, nearly, NOISE_U, NOISE_F).beyond_refit < 0.1
    # and what the restarts miss themselves is common to both: nothing for the truth
    assert shooting_separation(truth, stand, maxwell, maxwell, NOISE_U, NOISE_F).beyond_refit < 1e-6


def test_a_skew_and_a_gauge_low_pass_part_in_the_snatches() -> None:
    # Both delay the force ≈ 1 ms: on a taut fibre a refit makes them alike ...
    x, stand, rate = _motion(Shape.QUASI_SINUSOIDAL, 45.0, 1.0, 8.131)
    gentle = min(
        shooting_separation(
            _recorded(stand, (SKEW,), x, rate), stand, (SKEW,), (GAUGE,), NOISE_U, NOISE_F
        ).beyond_refit,
        shooting_separation(
            _recorded(stand, (GAUGE,), x, rate), stand, (GAUGE,), (SKEW,), NOISE_U, NOISE_F
        ).beyond_refit,
    )
    # ... a snatch of a slack fibre (a step of F) shows the gauge's ring and the skew's shift
    x, stand, rate = _motion(Shape.RECTANGULAR, 10.0, 1.5, 3.096)
    snatched = min(
        shooting_separation(
            _recorded(stand, (SKEW,), x, rate), stand, (SKEW,), (GAUGE,), NOISE_U, NOISE_F
        ).beyond_refit,
        shooting_separation(
            _recorded(stand, (GAUGE,), x, rate), stand, (GAUGE,), (SKEW,), NOISE_U, NOISE_F
        ).beyond_refit,
    )
    assert gentle < 0.5
    assert snatched > 1.5


def test_the_floor_is_the_noise_on_a_taut_fibre_and_more_after_snatches() -> None:
    # never slack: one open-loop run, the truth misses its noisy recording by the noise
    x, stand, rate = _motion(Shape.QUASI_SINUSOIDAL, 45.0, 1.0, 8.131)
    taut = shooting_separation(
        _recorded(stand, (SKEW,), x, rate, noisy=True), stand, (SKEW,), (GAUGE,), NOISE_U, NOISE_F
    )
    assert taut.channel_floor == pytest.approx((1.0, 1.0), rel=0.05)  # 1 noise unit each
    # snatches: restarts from states estimated on noisy channels miss a little more than
    # the noise, for the right model too (each start refined over its warm-up: 1.09; from
    # the cubic fit alone 2.0 and more); the rivals' difference counts against that floor
    x, stand, rate = _motion(Shape.RECTANGULAR, 10.0, 1.5, 3.096)
    snatched = shooting_separation(
        _recorded(stand, (SKEW,), x, rate, noisy=True), stand, (SKEW,), (GAUGE,), NOISE_U, NOISE_F
    )
    assert 1.0 < max(snatched.channel_floor) < 1.3
    ratios = [
        m / max(f, 1.0) for m, f in zip(snatched.channel_miss, snatched.channel_floor, strict=True)
    ]
    assert snatched.against_floor == pytest.approx(
        np.sqrt((1 + ratios[0] ** 2) * (1 + ratios[1] ** 2) - 1)
    )
    assert snatched.against_floor < max(snatched.channel_miss)


def test_effect_steps_stay_in_range_and_move_every_fitted_parameter() -> None:
    # a gauge at the top of its typical range: its step must not leave the admissible one
    specs = (SKEW, EffectSpec("force_gauge_dynamics", {"cutoff_hz": 300.0}))
    steps = effect_steps(specs)
    fitted = [
        f"{s.name}.{p.name}"
        for s in specs
        for p in EFFECTS[s.name].params
        if p.fit and not p.integer
    ]
    assert [key for step in steps for key in step] == fitted
    values = {f"{s.name}.{k}": v for s in specs for k, v in s.resolved().items()}
    for step in steps:
        ((key, value),) = step.items()
        effect, _, name = key.partition(".")
        param = EFFECTS[effect].param(name)
        assert param.minimum <= value <= param.maximum
        assert value != values[key]
