"""The safety prediction on its own: figures, limits, the spread, the stand file's keys."""

from __future__ import annotations

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import ConfigError, config_from_dict, default_config
from sim.envelope import NOMINAL_SPREAD, SlackRule, Spread, longest_run_s
from sim.prediction import predict

RULE = SlackRule(slack_force_n=2.0, slack_max_s=0.25)
#: No spread: the model's own values only (centre and eight equal corners).
POINT = Spread((1.0, 1.0), (1.0, 1.0), (1.0, 1.0))


def _x(spec: SignalSpec) -> np.ndarray:
    config = default_config()
    return plan_motion(spec, config.drive).sample(config.sample_rate_hz)[1]


def test_longest_run_is_timed_first_to_last_sample() -> None:
    mask = np.array([0, 1, 1, 1, 0, 1, 1, 1, 1, 1, 0], dtype=bool)
    assert longest_run_s(mask, 10.0) == pytest.approx(0.4)
    assert longest_run_s(np.zeros(5, dtype=bool), 10.0) == 0.0
    assert longest_run_s(np.ones(5, dtype=bool), 10.0) == pytest.approx(0.4)


def test_spread_corners_hold_the_centre_and_every_extreme() -> None:
    corners = NOMINAL_SPREAD.corners()
    assert corners[0] == (1.0, 1.0, 1.0) and len(corners) == 9
    assert {c[0] for c in corners[1:]} == {0.75, 1.25}
    moved = NOMINAL_SPREAD.around((2.0, 1.0, 0.0))
    assert moved.stiffness == (1.5, 2.5) and moved.friction == (0.0, 0.0)


def test_a_slow_quasi_sine_is_taut_and_the_weight_follows_the_drive() -> None:
    # Physics: at 0.5 Hz the heavy weight follows the 60 mm stroke quasi-statically, the
    # fibre stays taut, and the tension stays near m·g·(sin α + μ cos α) ≈ 45 N.
    config = default_config()
    x = _x(SignalSpec(Shape.QUASI_SINUSOIDAL, 0.060, 0.5, cycles=2))
    stand = config.stand_params("final", 8.131)
    p = predict(stand, (), x, config.sample_rate_hz, NOMINAL_SPREAD, RULE.slack_force_n)
    assert p.worst.slack_share == 0.0 and p.worst.longest_slack_s == 0.0
    assert 0.058 < p.nominal.weight_travel_m < 0.075  # the stroke, stretched a little
    assert 40.0 < p.nominal.peak_tension_n < 70.0
    assert not p.breaches(config.envelope, RULE)
    assert all(m > 0 for m in p.margins(config.envelope, RULE).values())


def test_the_readme_example_breaks_every_limit_even_at_the_model_s_own_values() -> None:
    config = default_config()
    x = _x(SignalSpec(Shape.TRAPEZOIDAL, 0.060, 2.0, cycles=5))
    stand = config.stand_params("final", 8.131)
    p = predict(stand, (), x, config.sample_rate_hz, POINT, RULE.slack_force_n)
    # the figures `labstand simulate` prints for it: slack 67.9 %, u up to 373 mm
    assert p.nominal.slack_share == pytest.approx(0.679, abs=0.005)
    assert p.nominal.weight_travel_m == pytest.approx(0.373, abs=0.002)
    breaches = p.breaches(config.envelope, RULE)
    assert [b.split(" (")[0].rsplit(" ", 2)[0] for b in breaches] == [
        "weight travel",
        "peak tension",
        "fibre slack",
    ]
    assert breaches[0] == "weight travel 373 mm (limit 120 mm)"


def test_the_spread_only_ever_makes_the_worst_case_worse() -> None:
    config = default_config()
    x = _x(SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=3))
    stand = config.stand_params("final", 8.131)
    point = predict(stand, (), x, config.sample_rate_hz, POINT, RULE.slack_force_n)
    wide = predict(stand, (), x, config.sample_rate_hz, NOMINAL_SPREAD, RULE.slack_force_n)
    assert wide.nominal == point.nominal
    assert wide.worst.peak_tension_n > point.worst.peak_tension_n
    assert wide.worst.longest_slack_s >= point.worst.longest_slack_s


def test_a_stiffer_fibre_pulls_harder_in_a_snatch() -> None:
    config = default_config()
    x = _x(SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=3))
    stand = config.stand_params("final", 8.131)
    soft, stiff = (
        predict(stand, (), x, config.sample_rate_hz, POINT.around((k, 1.0, 1.0)), 2.0)
        for k in (0.5, 2.0)
    )
    assert stiff.nominal.peak_tension_n > 1.2 * soft.nominal.peak_tension_n


def test_the_stand_file_holds_the_limits() -> None:
    config = config_from_dict({"safety": {"weight_travel_max_mm": 80, "fibre_tension_max_n": 150}})
    assert config.envelope.weight_travel_max_m == pytest.approx(0.080)
    assert config.envelope.fibre_tension_max_n == 150.0
    assert default_config().envelope.weight_travel_max_m == pytest.approx(0.120)
    with pytest.raises(ConfigError, match=r"\[safety\] fibre_tension_max_n: must be > 0"):
        config_from_dict({"safety": {"fibre_tension_max_n": -1}})
    with pytest.raises(ConfigError, match=r"\[safety\] travel: unknown key"):
        config_from_dict({"safety": {"travel": 1}})
