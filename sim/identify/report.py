"""The diagnosis as a typed report: what the CLI prints, the JSON, and the HTML page read."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from sim.identify.decide import ALPHA
from sim.identify.heldout import Outputs
from sim.identify.remainder import Remainder
from sim.identify.where import Where

__all__ = ["AcceptedEffect", "ChannelGap", "Diagnosis", "Intervals", "RankedEffect"]

#: Per channel (``u``, ``F``): R, psi and NRMSE on the held-out samples.
ChannelGap = dict[str, dict[str, float]]
#: A 95 % interval per parameter: ``{name: (low, high)}``.
Intervals = dict[str, tuple[float, float]]


@dataclass
class RankedEffect:
    """One candidate's line in the ranking (each alone on top of the baseline)."""

    effect: str
    #: Share of the baseline residual the screening probe explained.
    screening: float
    #: Held-out gap closure; None when the candidate was not refitted.
    score: float | None = None
    #: Held-out RMS of the channels' NRMSE.
    heldout_error: float | None = None
    #: Held-out error in noise units (what the score is made of; 1 = perfect).
    heldout_excess: float | None = None
    #: One-sided p-value of its held-out gain over the baseline (single test).
    p_value: float | None = None
    #: The same as one of the family of candidates (``decide.judge``): what ALPHA judges.
    p_family: float | None = None
    params: dict[str, float] = field(default_factory=dict)
    #: Fitted parameters that ended on a bound of their physical range: the effect may be
    #: larger than the range allows, or of another form.
    at_bound: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """JSON keys effect, score, heldout_error, heldout_excess, p_value, p_family, ..."""
        return {
            "effect": self.effect,
            "score": self.score,
            "heldout_error": self.heldout_error,
            "heldout_excess": self.heldout_excess,
            "p_value": self.p_value,
            "p_family": self.p_family,
            "screening": self.screening,
            "params": self.params,
            "at_bound": self.at_bound,
        }


@dataclass
class AcceptedEffect:
    """An effect the diagnosis names, in the order it was accepted.

    ``closure`` is the share of the baseline's gap above the noise that adding this effect
    (on top of those before it) closed on held-out cycles; ``p_value`` its test against
    the model before it, as one of the family of candidates tried at that step (``decide.judge``).
    ``indistinguishable_from``: candidates that explain the same part of the gap about
    as well — the recordings cannot tell them apart from this one.
    """

    effect: str
    closure: float
    p_value: float
    params: dict[str, float]
    at_bound: list[str] = field(default_factory=list)
    indistinguishable_from: list[str] = field(default_factory=list)
    #: 95 % intervals of ``params`` (the method: ``Diagnosis.interval_method``).
    intervals: Intervals = field(default_factory=dict)
    #: Parameters whose interval reaches their physical bound: the recordings cannot say
    #: how far beyond it they would go.
    reaches_bound: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """JSON keys effect, closure, p_value, params, intervals, at_bound, ..."""
        return {
            "effect": self.effect,
            "closure": self.closure,
            "p_value": self.p_value,
            "params": self.params,
            "intervals": _listed(self.intervals),
            "reaches_bound": self.reaches_bound,
            "at_bound": self.at_bound,
            "indistinguishable_from": self.indistinguishable_from,
        }


@dataclass
class Diagnosis:
    """The answer: the typed report the CLI and the HTML page both read (``to_dict``: JSON)."""

    effects: list[AcceptedEffect]
    ranking: list[RankedEffect]
    where: Where
    gap_before: ChannelGap
    gap_after: ChannelGap
    baseline: dict[str, float]
    heldout_error_before: float
    heldout_error_after: float
    noise_floor: float
    gap_closure: float
    confidence: float
    #: Family-wise false-alarm rate of each decision.
    alpha: float = ALPHA
    timings_s: dict[str, float] = field(default_factory=dict)
    simulations: int = 0
    outputs_before: list[Outputs] = field(default_factory=list, repr=False)
    outputs_after: list[Outputs] = field(default_factory=list, repr=False)
    #: One of ``remainder.VERDICTS``: what the named effects leave.
    verdict: str = "baseline_adequate"
    remainder: Remainder | None = None
    #: Effects that passed their test but did no better than a signature of the
    #: remainder (effect → the signature's kind): not named.
    displaced: dict[str, str] = field(default_factory=dict)
    #: 95 % intervals of ``baseline`` (stiffness_scale, damping_scale, friction_scale).
    baseline_intervals: Intervals = field(default_factory=dict)
    baseline_reaches_bound: list[str] = field(default_factory=list)
    gap_closure_interval: tuple[float, float] | None = None
    #: Per channel, the held-out NRMSE's 95 % interval before and after the named effects:
    #: ``{"before": {"u": (lo, hi), "F": ...}, "after": {...}}``.
    gap_intervals: dict[str, Intervals] = field(default_factory=dict)
    #: How the intervals were found, in words.
    interval_method: str = ""
    #: Parameters fitted per recording: ``{name: {"params": {...}, "intervals": {...},
    #: "drive_rate_hz": f, "amplitude_m": a, "mass_kg": m}}``.
    per_recording: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: Do the per-recording fits agree: ``{parameter: {"p_value": p, "trend": words|None}}``.
    consistency: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: The same for the baseline alone fitted per recording (where effects are named;
    #: else the same as ``consistency``): what the named effects took out of the trends.
    baseline_consistency: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: The fibre's storage stiffness against its strain rate (``dynamic_stiffness``), for
    #: ``baseline_alone`` and, where effects are named, the ``final`` model.
    dynamic_stiffness: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def effect(self) -> str:
        """The strongest effect (the first accepted), or ``none``."""
        return self.effects[0].effect if self.effects else "none"

    def to_dict(self) -> dict[str, Any]:
        """JSON keys: effect, effects, ranking, where, gap_before, gap_after, and details."""
        return {
            "effect": self.effect,
            "verdict": self.verdict,
            "effects": [e.to_dict() for e in self.effects],
            "remainder": self.remainder.to_dict() if self.remainder is not None else None,
            "displaced": self.displaced,
            "ranking": [r.to_dict() for r in self.ranking],
            "where": self.where.to_dict(),
            "gap_before": self.gap_before,
            "gap_after": self.gap_after,
            "baseline_fit": self.baseline,
            "heldout_error_before": self.heldout_error_before,
            "heldout_error_after": self.heldout_error_after,
            "noise_floor": self.noise_floor,
            "gap_closure": self.gap_closure,
            "alpha": self.alpha,
            "confidence": self.confidence,
            "simulations": self.simulations,
            "timings_s": self.timings_s,
            "baseline_intervals": _listed(self.baseline_intervals),
            "baseline_reaches_bound": self.baseline_reaches_bound,
            "gap_closure_interval": (
                list(self.gap_closure_interval) if self.gap_closure_interval else None
            ),
            "gap_intervals": {k: _listed(v) for k, v in self.gap_intervals.items()},
            "interval_method": self.interval_method,
            "per_recording": self.per_recording,
            "consistency": self.consistency,
            "baseline_consistency": self.baseline_consistency,
            "dynamic_stiffness": self.dynamic_stiffness,
        }


def _listed(intervals: Intervals) -> dict[str, list[float]]:
    """JSON has no tuples: each interval as ``[low, high]``."""
    return {name: [float(lo), float(hi)] for name, (lo, hi) in intervals.items()}
