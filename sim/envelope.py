"""What a motion may do to the stand, and what the model predicts it does.

The stand file's ``[safety]`` table gives what the stand survives: how far the weight may
travel in its guide and the fibre's safe peak tension. The run's slack e-stop rule
(``labstand.session.safety``) adds how long the fibre may stay slack. A prediction
(``sim.prediction.predict``) simulates a motion at the corners of a plausible range of
the baseline's uncertain parameters (``Spread``) and keeps each figure's worst; a motion
is admissible when no worst figure breaks its limit.

Numpy only: the stand file's loader imports this module, the model is in
``sim.prediction``.
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "FITTED_SPREAD",
    "NOMINAL_SPREAD",
    "MotionFigures",
    "Prediction",
    "SlackRule",
    "Spread",
    "StandEnvelope",
    "figures_of",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class StandEnvelope:
    """What the stand survives (the stand file's ``[safety]``, [estimate] by default).

    Attributes
    ----------
    weight_travel_max_m
        How far the weight may move from its rest position along its guide, either way, m
        (the paper's weight was once flung out of its prismatic linkage).
    fibre_tension_max_n
        The fibre's safe peak tension, N.
    """

    weight_travel_max_m: float
    fibre_tension_max_n: float


@dataclass(frozen=True)
class SlackRule:
    """The run's slack e-stop: F below ``slack_force_n`` for longer than ``slack_max_s``."""

    slack_force_n: float
    slack_max_s: float


@dataclass(frozen=True)
class Spread:
    """A plausible range of the baseline's uncertain parameters, as multipliers.

    Each is a factor on the stand's nominal value: fibre stiffness, fibre damping, and
    the scale of the weight–guide friction table (a diagnosis' ``baseline_fit`` scales
    are such factors). ``centre`` is the model's own value, each range (low, high)
    holds it.
    """

    stiffness: tuple[float, float]
    damping: tuple[float, float]
    friction: tuple[float, float]
    centre: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def around(self, centre: tuple[float, float, float]) -> Spread:
        """The same relative range about another centre."""
        s, d, f = centre
        return Spread(
            (s * self.stiffness[0], s * self.stiffness[1]),
            (d * self.damping[0], d * self.damping[1]),
            (f * self.friction[0], f * self.friction[1]),
            centre,
        )

    def corners(self) -> list[tuple[float, float, float]]:
        """The centre, then the range's 8 corners: (stiffness, damping, friction) factors."""
        ranges = (self.stiffness, self.damping, self.friction)
        return [self.centre, *itertools.product(*ranges)]


#: About the nominal model [estimate]: the diagnosis' validation draws stands ±25 % off
#: nominal in stiffness; damping and friction are known worse (the paper tuned them by
#: hand per situation), hence ×0.5 … ×1.5.
NOMINAL_SPREAD = Spread(stiffness=(0.75, 1.25), damping=(0.5, 1.5), friction=(0.5, 1.5))
#: About a diagnosis' fitted values when it gives no intervals [estimate]: half the
#: nominal range.
FITTED_SPREAD = Spread(stiffness=(0.875, 1.125), damping=(0.75, 1.25), friction=(0.75, 1.25))


@dataclass(frozen=True)
class MotionFigures:
    """What one simulated motion does to the stand.

    Attributes
    ----------
    peak_tension_n
        Largest fibre tension, N.
    longest_slack_s
        Longest stretch with the (recorded) force below the slack rule's threshold, s.
    slack_share
        Share of the time the fibre carries no tension.
    weight_travel_m
        Largest distance of the weight from its rest position, m.
    """

    peak_tension_n: float
    longest_slack_s: float
    slack_share: float
    weight_travel_m: float

    def to_dict(self) -> dict[str, float]:
        """JSON: the fields, travel in mm."""
        out = asdict(self)
        out["weight_travel_mm"] = out.pop("weight_travel_m") * 1e3
        return out


def longest_run_s(mask: NDArray[np.bool_], rate_hz: float) -> float:
    """Longest stretch of True samples, s, timed as the e-stop does (first to last sample)."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    if starts.size == 0:
        return 0.0
    return float((ends - starts).max() - 1) / rate_hz


def figures_of(
    true_force_n: FloatArray,
    recorded_force_n: FloatArray,
    true_u_m: FloatArray,
    rate_hz: float,
    slack_force_n: float,
) -> MotionFigures:
    """The figures of one run: tension and travel of the true channels, slack as recorded.

    The slack rule acts on what the force gauge reports, the fibre and the guide feel
    the true tension and travel.
    """
    return MotionFigures(
        peak_tension_n=float(true_force_n.max()),
        longest_slack_s=longest_run_s(recorded_force_n < slack_force_n, rate_hz),
        slack_share=float(np.mean(true_force_n <= 0.0)),
        weight_travel_m=float(np.abs(true_u_m).max()),
    )


@dataclass(frozen=True)
class Prediction:
    """A motion's figures at the model's values and the worst over the plausible range.

    Attributes
    ----------
    nominal
        At the model's own values (the range's centre).
    worst
        Each figure's worst over the range's corners and centre.
    runs
        How many parameter sets were simulated.
    """

    nominal: MotionFigures
    worst: MotionFigures
    runs: int

    def _checks(self, envelope: StandEnvelope, rule: SlackRule) -> list[tuple[str, float, float]]:
        """(what, worst value, limit) in display units."""
        w = self.worst
        return [
            ("weight travel", w.weight_travel_m * 1e3, envelope.weight_travel_max_m * 1e3),
            ("peak tension", w.peak_tension_n, envelope.fibre_tension_max_n),
            ("fibre slack", w.longest_slack_s, rule.slack_max_s),
        ]

    def breaches(self, envelope: StandEnvelope, rule: SlackRule) -> list[str]:
        """Each limit the worst case breaks, as 'what VALUE (limit LIMIT)'; empty if none."""
        units = {"weight travel": "mm", "peak tension": "N", "fibre slack": "s"}
        return [
            f"{what} {_num(value)} {units[what]} (limit {_num(limit)} {units[what]})"
            for what, value, limit in self._checks(envelope, rule)
            if value > limit
        ]

    def margins(self, envelope: StandEnvelope, rule: SlackRule) -> dict[str, float]:
        """Each limit's margin over the worst case, as a share of the limit (< 0: broken)."""
        return {
            what.replace(" ", "_"): 1.0 - value / limit
            for what, value, limit in self._checks(envelope, rule)
        }

    def summary(self) -> str:
        """The worst figures in one phrase."""
        w = self.worst
        return (
            f"slack {w.slack_share:.0%} of the time (longest {w.longest_slack_s:.2f} s), "
            f"peak {w.peak_tension_n:.0f} N, weight travel {w.weight_travel_m * 1e3:.0f} mm"
        )

    def to_dict(self, envelope: StandEnvelope, rule: SlackRule) -> dict[str, object]:
        """JSON: nominal and worst figures, the margins, the limits."""
        return {
            "nominal": self.nominal.to_dict(),
            "worst": self.worst.to_dict(),
            "runs": self.runs,
            "margins": self.margins(envelope, rule),
            "limits": {
                "weight_travel_mm": envelope.weight_travel_max_m * 1e3,
                "peak_tension_n": envelope.fibre_tension_max_n,
                "longest_slack_s": rule.slack_max_s,
            },
        }


def _num(value: float) -> str:
    return f"{value:.2f}" if abs(value) < 10 else f"{value:.0f}"


def worst_of(figures: list[MotionFigures]) -> MotionFigures:
    """Each figure's largest value over several runs."""
    return MotionFigures(
        peak_tension_n=max(f.peak_tension_n for f in figures),
        longest_slack_s=max(f.longest_slack_s for f in figures),
        slack_share=max(f.slack_share for f in figures),
        weight_travel_m=max(f.weight_travel_m for f in figures),
    )
