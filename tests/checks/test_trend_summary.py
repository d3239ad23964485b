"""The check's per-recording trend figures: what counts as a relaxation branch's pointer."""

from __future__ import annotations

from sim.checks.check import Case
from sim.checks.summaries import trend_summary

BRANCH_WORDS = (
    "damping that falls with frequency, as a relaxation branch's does (fibre_viscoelastic)"
)


def _case(truth: str, trends: dict[str, str], points_to: dict[str, str]) -> Case:
    return Case(truth, 8.131, truth, {}, 0.0, 0.0, 1.0, trends=trends, points_to=points_to)


def test_a_branch_is_counted_through_whichever_scale_carries_it() -> None:
    cases = [
        # the stiffness follows the rate: both counts
        _case("fibre_viscoelastic", {"stiffness_scale": "drive_rate_hz+stroke_m"},
              {"stiffness_scale": "a relaxation branch in the fibre (fibre_viscoelastic)"}),
        # only the damping carries it: a pointer, not a stiffness trend
        _case("fibre_viscoelastic", {"damping_scale": "drive_rate_hz"},
              {"damping_scale": BRANCH_WORDS}),
        # the stiffness follows the stroke alone: neither count
        _case("fibre_viscoelastic", {"stiffness_scale": "stroke_m"},
              {"stiffness_scale": "a fibre that stiffens with strain (a nonlinear law)"}),
        # the fibre's law stiffer at quicker strain rates, the per-recording fits flat
        _case("fibre_viscoelastic", {"dynamic_stiffness": "strain_rate_hz"},
              {"dynamic_stiffness": "a relaxation branch in the fibre (fibre_viscoelastic)"}),
        _case("none", {}, {}),
        _case("none", {"friction_scale": "drive_rate_hz"},
              {"friction_scale": "friction that grows with speed (a drag term)"}),
    ]  # fmt: skip
    got = trend_summary(cases)
    assert got["fibre_viscoelastic"] == {
        "stiffness_with_rate": 1 / 4, "stiffness_with_strain_rate": 1 / 4, "flagged": 2 / 4,
        "points_to_branch": 3 / 4, "campaigns": 4,
    }  # fmt: skip
    assert got["none"] == {
        "stiffness_with_rate": 0.0, "stiffness_with_strain_rate": 0.0, "flagged": 0.0,
        "points_to_branch": 0.0, "campaigns": 2,
    }  # fmt: skip
