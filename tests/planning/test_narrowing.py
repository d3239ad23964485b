"""The plan's second job: the test that narrows the widest interval most."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from labstand.fitted import fitted_from_dict
from labstand.planning import narrowing_for, widest_interval
from sim.config import default_config
from sim.discrimination import parameter_information, recording_of
from sim.effects import EffectSpec
from sim.model import Model
from sim.planner import Narrowing, Noise, score

NOISE = Noise(u_m=5e-6, force_n=0.1)
BRANCH = EffectSpec(
    "fibre_viscoelastic", {"branch_stiffness_n_m": 2.0e4, "relaxation_time_s": 0.03}
)
TAU = "fibre_viscoelastic.relaxation_time_s"
HEAVY = 8.131


def _recording(cycles: int, frequency_hz: float = 1.0, amplitude_mm: float = 20.0):  # type: ignore[no-untyped-def]
    config = default_config()
    spec = SignalSpec(Shape.TRAPEZOIDAL, amplitude_mm / 1e3, frequency_hz, cycles, 0.3, 0.5, 0.5)
    x = plan_motion(spec, config.drive).sample(config.sample_rate_hz)[1]
    stand = config.stand_params("final", HEAVY)
    run = Model(stand, (BRANCH,)).run(x, config.sample_rate_hz)
    noise = (NOISE.u_m, NOISE.force_n)
    rec = recording_of("branch", x, run.u_m, run.force_n, config.sample_rate_hz, HEAVY, noise)
    return rec, stand


def test_information_adds_up_over_the_cycles_of_a_test() -> None:
    # Information is a sum over the samples: twice the cycles of the same motion hold
    # about twice as much about the branch's relaxation time (the rest around them and
    # the first cycle's start make it a little less than twice).
    short, stand = _recording(2)
    long, _ = _recording(4)
    i_short = parameter_information(short, stand, (BRANCH,), TAU, NOISE.u_m, NOISE.force_n)
    i_long = parameter_information(long, stand, (BRANCH,), TAU, NOISE.u_m, NOISE.force_n)
    assert i_short > 0.0
    assert 1.5 < i_long / i_short < 2.5


def test_a_parameter_outside_the_model_is_refused() -> None:
    rec, stand = _recording(2)
    with pytest.raises(ValueError, match="not a fitted parameter"):
        parameter_information(rec, stand, (BRANCH,), "channel_time_skew.force_skew_s", 1.0, 1.0)


def test_the_predicted_interval_shrinks_with_the_information_added() -> None:
    narrow = Narrowing("b", TAU, 0.030, (0.026, 0.036), held=10.0)
    assert narrow.predicted(0.0) == pytest.approx((0.026, 0.036))
    low, high = narrow.predicted(30.0) or (0.0, 0.0)  # four times the information: half
    assert (low, high) == pytest.approx((0.028, 0.033))
    assert Narrowing("b", TAU, 0.030, (0.026, 0.036)).predicted(30.0) is None  # held unknown


def test_among_motions_that_settle_every_pair_the_more_informative_wins() -> None:
    settled = {("a", "none"): 2.0}
    assert score(settled, 5.0) > score({("a", "none"): 3.0}, 1.0)
    # the interval counts only once the rivals are told apart
    assert score({("a", "none"): 0.6}, 0.0) > score({("a", "none"): 0.5}, 100.0)
    assert score({("a", "none"): 2.0, ("b", "none"): 0.5}, 100.0)[1] == 0.0


def _diagnosis(intervals: dict[str, list[float]]) -> dict:  # type: ignore[type-arg]
    return {
        "baseline_fit": {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0},
        "effects": [
            {
                "effect": "fibre_viscoelastic",
                "params": {"branch_stiffness_n_m": 2.0e4, "relaxation_time_s": 0.03},
                "intervals": intervals,
            }
        ],
    }


def test_the_widest_interval_is_the_widest_against_its_value() -> None:
    fitted = fitted_from_dict(
        _diagnosis({"branch_stiffness_n_m": [1.9e4, 2.1e4], "relaxation_time_s": [0.027, 0.034]}),
        Path("d.json"),
    )
    assert widest_interval(fitted) == (TAU, 0.03, (0.027, 0.034))  # ±12 % against ±5 %
    held = fitted_from_dict(_diagnosis({"relaxation_time_s": [0.03, 0.03]}), Path("d.json"))
    assert widest_interval(held) is None  # a level, not an interval


def test_the_recordings_information_is_what_the_prediction_counts_from() -> None:
    config = default_config()
    fitted = fitted_from_dict(_diagnosis({"relaxation_time_s": [0.027, 0.034]}), Path("d.json"))
    rec, stand = _recording(2)
    narrowing = narrowing_for(fitted, config, NOISE, [rec])
    assert narrowing is not None and narrowing.key == TAU
    alone = parameter_information(rec, stand, (BRANCH,), TAU, NOISE.u_m, NOISE.force_n)
    assert narrowing.held == pytest.approx(alone, rel=1e-9)
    # the same test again would hold as much: the interval by 1/√2
    low, high = narrowing.predicted(alone) or (0.0, 0.0)
    assert high - low == pytest.approx((0.034 - 0.027) / np.sqrt(2.0), rel=1e-9)
    assert narrowing_for(fitted, config, NOISE) is not None
    assert narrowing_for(fitted, config, NOISE).held is None  # type: ignore[union-attr]


def test_only_a_parameter_a_refit_moves_is_narrowed() -> None:
    # A diagnosis file whose widest interval is on a parameter no refit moves (the dial
    # gauge's offset: the recordings count u from rest) is passed over for the next
    # widest: the search could not measure what a test tells of it.
    data = _diagnosis({})
    data["effects"] = [
        {
            "effect": "dial_gauge_calibration",
            "params": {"gain_error": 0.05, "offset_m": 1e-5},
            "intervals": {"gain_error": [0.04, 0.06], "offset_m": [-1e-4, 1e-4]},
        }
    ]
    fitted = fitted_from_dict(data, Path("d.json"))
    assert widest_interval(fitted) == ("dial_gauge_calibration.offset_m", 1e-5, (-1e-4, 1e-4))
    narrowing = narrowing_for(fitted, default_config(), NOISE)
    assert narrowing is not None and narrowing.key == "dial_gauge_calibration.gain_error"
