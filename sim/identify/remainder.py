"""What remains after the named effects: a gap beyond noise or not, and what it is like.

The held-out error of a model that is right is not exactly the sensor noise: a chaotic
bounce on a slack fibre (the light weight) follows no model past a few bounces, and the
noise is known only to about a tenth. So "beyond noise" is not "X above 1". It is a
*systematic* remainder: one that the training cycles show and the held-out cycles
confirm. Every kind of term of the signature library (``signature``) is fitted to the
training cycles' remainder and predicts the held-out cycles'; the kinds are judged as
one family against the model by the effects' own test (``decide.judge``): random sign
flips of whole held-out blocks, maxT over the kinds. A remainder stands if some kind's
gain passes at ``ALPHA``: a model that is right is called inadequate at most that often,
by construction, whatever the noise.

The verdict joins that with the named effects (``VERDICTS``):

* ``baseline_adequate``: nothing named, and no systematic remainder;
* ``explained``: effects named, and none remains;
* ``partly_explained``: effects named, and a remainder stands;
* ``unexplained``: a remainder stands that no candidate effect closes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from sim.identify.decide import ALPHA, Evidence, judge
from sim.identify.heldout import Outputs, heldout_excess
from sim.identify.signature import Signature, SignatureFit, fit_signatures
from sim.identify.traces import Trace
from sim.identify.where import Where
from sim.params import StandParams

__all__ = ["VERDICTS", "Remainder", "judge_signatures", "remainder_of", "verdict"]

VERDICTS = ("baseline_adequate", "explained", "partly_explained", "unexplained")
#: The verdicts in words (the CLI's first line).
VERDICT_WORDS = {
    "baseline_adequate": "baseline adequate: no systematic gap beyond the noise",
    "explained": "explained: the named effects close the gap to the noise",
    "partly_explained": "partly explained: the named effects leave a systematic remainder",
    "unexplained": "unexplained: a systematic gap that no candidate effect closes",
}


@dataclass
class Remainder:
    """The held-out remainder of the final model (after the named effects)."""

    beyond_noise: bool
    #: The family p-value of the best-supported signature kind (1 if none was fitted).
    p_value: float
    #: The final model's held-out error in noise units (1 = the noise alone).
    excess: float
    #: Share of the baseline's gap above the noise (X − 1) that remains.
    share_of_gap: float
    where: Where | None
    #: Every kind, best held-out closure first; those that pass are the description.
    signature: list[Signature] = field(default_factory=list)
    #: The fits behind ``signature`` (for plots), by kind.
    fits: dict[str, SignatureFit] = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict[str, object]:
        """JSON keys beyond_noise, p_value, excess, share_of_gap, where, signature."""
        return {
            "beyond_noise": self.beyond_noise,
            "p_value": self.p_value,
            "excess": self.excess,
            "share_of_gap": self.share_of_gap,
            "where": self.where.to_dict() if self.where is not None else None,
            "signature": [s.to_dict() for s in self.signature if s.passes],
            "kinds_tried": [s.to_dict() for s in self.signature],
        }


def judge_signatures(
    traces: Sequence[Trace],
    outputs: Sequence[Outputs],
    nominal: StandParams,
    values: dict[str, float],
) -> tuple[list[Signature], dict[str, SignatureFit], dict[str, Evidence]]:
    """Every signature kind fitted to the remainder of ``outputs`` and judged as a family.

    Returns the signatures (best held-out closure first), their fits and evidence by kind.
    """
    fits = {f.kind: f for f in fit_signatures(traces, outputs, nominal, values)}
    evidence = judge(traces, outputs, {k: f.outputs for k, f in fits.items()})
    x_before = heldout_excess(traces, outputs)
    signatures = []
    for kind, fit in fits.items():
        ev = evidence[kind]
        signatures.append(
            Signature(
                kind=kind,
                channel=fit.channel,
                formula=fit.formula,
                closes=(x_before - ev.x_after) / max(x_before - 1.0, 1e-12),
                excess_after=ev.x_after,
                p_family=ev.corrected_p(len(fits)),
                passes=ev.accepted(len(fits)),
            )
        )
    signatures.sort(key=lambda s: (not s.passes, s.excess_after))
    return signatures, fits, evidence


def remainder_of(
    traces: Sequence[Trace],
    outputs: Sequence[Outputs],
    nominal: StandParams,
    values: dict[str, float],
    x_base: float,
    where: Where | None = None,
) -> Remainder:
    """The final model's remainder: judged, described, and its share of the baseline's gap."""
    signatures, fits, _ = judge_signatures(traces, outputs, nominal, values)
    excess = heldout_excess(traces, outputs)
    passing = [s for s in signatures if s.passes]
    p_value = min((s.p_family for s in signatures), default=1.0)
    share = (excess - 1.0) / (x_base - 1.0) if x_base > 1.0 else 0.0
    return Remainder(
        beyond_noise=bool(passing),
        p_value=p_value,
        excess=excess,
        share_of_gap=min(max(share, 0.0), 1.0),
        where=where,
        signature=signatures,
        fits=fits,
    )


def verdict(named: bool, remainder: Remainder) -> str:
    """One of ``VERDICTS`` from whether effects were named and what remains."""
    if named:
        return "partly_explained" if remainder.beyond_noise else "explained"
    return "unexplained" if remainder.beyond_noise else "baseline_adequate"


#: The family-wise false-alarm rate of the remainder's test (the effects' own).
REMAINDER_ALPHA = ALPHA
