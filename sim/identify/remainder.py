"""What remains after the named effects: a gap beyond noise or not, and what it is like.

The held-out error of a model that is right is not exactly the sensor noise: a chaotic
bounce on a slack fibre (the light weight) follows no model past a few bounces, and the
noise is known only to about a tenth. So "beyond noise" is not "X above 1". It is a
*systematic* remainder: one that the training cycles show and the held-out cycles
confirm. Every kind of term of the signature library (``signature``) is fitted to the
training cycles' remainder and predicts the held-out cycles'; the kinds are judged as
one family against the model by the effects' own test (``decide.judge``): random sign
flips of whole held-out blocks, maxT over the kinds. A remainder stands if some kind's
gain passes at ``REMAINDER_ALPHA``: a model that is right is called inadequate at most
that often, by construction, whatever the noise. Where nothing is named, it stands too
where the held-out error is beyond anything the fitted model leaves on recordings of its
own (``adequacy``): a misfit too irregular for any signature, on recordings too few to
say what it is, is not "adequate". Where effects are named that comparison is reported
but does not decide: the named effect's fit a little off its best (as the intervals'
misses show, the right effect named left up to twice its replicates' error on fresh
seeds) and a slack fibre's bounces, whose tail eight replicates do not bound, put a
right model past it (``make demo``: 3.07 against a bound of 3.03).

The verdict joins that with the named effects (``VERDICTS``):

* ``baseline_adequate``: nothing named, and no systematic remainder;
* ``explained``: effects named, and none remains;
* ``partly_explained``: effects named, and a remainder stands;
* ``unexplained``: a remainder stands that no candidate effect closes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from sim.identify.adequacy import OwnExcess, own_excess
from sim.identify.balance import fit_balances
from sim.identify.decide import (
    ALPHA,
    Evidence,
    block_gains,
    family_p_values,
    p_value_of_gains,
)
from sim.identify.fitting import Candidate
from sim.identify.heldout import Outputs, heldout_excess
from sim.identify.signature import (
    BalanceSeries,
    Signature,
    SignatureFit,
    fit_baseline_terms,
    fit_signatures,
)
from sim.identify.traces import Trace
from sim.identify.where import Where
from sim.params import StandParams

__all__ = ["VERDICTS", "Remainder", "judge_signatures", "remainder_of", "verdict"]

VERDICTS = ("baseline_adequate", "explained", "partly_explained", "unexplained")
#: Family-wise false-alarm rate of the remainder's test. A right model can be called
#: wrong by either test (an effect named, or a remainder beyond the noise), so their
#: rates add: half the effects' ``ALPHA`` keeps the two together near it.
REMAINDER_ALPHA = ALPHA / 2
#: The verdicts in words (the CLI's first line).
VERDICT_WORDS = {
    "baseline_adequate": "baseline adequate: no systematic gap beyond the noise",
    "explained": "explained: the named effects close the gap to the noise",
    "partly_explained": "partly explained: the named effects leave a remainder beyond the noise",
    "unexplained": "unexplained: a gap beyond the noise that no candidate effect closes",
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
    #: Every kind, those that pass first (a formula before ``other``), then by held-out
    #: error; those that pass are the description.
    signature: list[Signature] = field(default_factory=list)
    #: The fits behind ``signature`` (for plots), by ``SignatureFit.name``.
    fits: dict[str, SignatureFit] = field(default_factory=dict, repr=False)
    #: The held-out excess against the fitted model's own replicates (None: not tested).
    own: OwnExcess | None = None

    @property
    def state(self) -> str:
        """What remains, in words (the CLI's and the report's)."""
        if not self.beyond_noise:
            return "within what the noise allows"
        if any(s.passes for s in self.signature):
            return "beyond the noise"
        assert self.own is not None
        return (
            f"beyond the noise: the held-out error is {self.own.observed:.3g} × the noise, "
            f"where the fitted model leaves at most {self.own.bound:.3g} × on recordings of "
            "its own, but no signature term repeats from cycle to cycle — the recordings are "
            "too few, or the misfit too irregular, to say what it is"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON keys beyond_noise, p_value, excess, share_of_gap, where, signature, own_excess."""
        return {
            "beyond_noise": self.beyond_noise,
            "p_value": self.p_value,
            "excess": self.excess,
            "share_of_gap": self.share_of_gap,
            "where": self.where.to_dict() if self.where is not None else None,
            "signature": [s.to_dict() for s in self.signature if s.passes],
            "kinds_tried": [s.to_dict() for s in self.signature],
            "own_excess": self.own.to_dict() if self.own is not None else None,
        }


def judge_signatures(
    traces: Sequence[Trace],
    outputs: Sequence[Outputs],
    nominal: StandParams,
    values: dict[str, float],
    balances: bool = False,
    in_miss_units: bool = False,
    beyond_baseline_terms: bool = False,
) -> tuple[list[Signature], dict[str, SignatureFit], dict[str, Evidence]]:
    """Every signature variant fitted to the remainder of ``outputs``, judged as a family.

    ``balances``: the force balances' variants too (``balance``; only where no effect is
    named: they know none), in the same family — the same held-out blocks, the same
    sign flips. ``in_miss_units``: the variants fitted in the units of the model's miss
    (``signature.fit_signatures``). ``beyond_baseline_terms``: each fitted kind judged
    against the baseline's own terms refitted alone (``signature.fit_baseline_terms``),
    not against the model: every kind is fitted beside those terms, and a model a hair
    off its least cost let them pass all kinds alike (a light Maxwell branch named, X
    0.9972 → 0.9970 at p 0.005 for any kind: ``partly_explained`` at the noise).
    Returns the signatures (those that pass first), the output-space fits and the
    evidence, by name (a kind and where it acts).
    """
    fits = {f.name: f for f in fit_signatures(traces, outputs, nominal, values, in_miss_units)}
    names = list(fits)
    reference = {n: outputs for n in names}
    if beyond_baseline_terms:
        terms = fit_baseline_terms(traces, outputs, nominal, values, in_miss_units).outputs
        # ``other`` (the training cycles' mean) is no fit beside them: against the model.
        reference.update({n: terms for n in names if fits[n].kind != "other"})
    rows = [block_gains(traces, reference[n], fits[n].outputs) for n in names]
    x_after = {n: heldout_excess(traces, fits[n].outputs) for n in names}
    before = {n: heldout_excess(traces, reference[n]) for n in names}
    info = {n: (fits[n].kind, fits[n].channel, fits[n].formula, "outputs") for n in names}
    resolution: dict[str, float] = {}
    series: dict[str, tuple[BalanceSeries, ...]] = {}
    if balances:
        for fit in fit_balances(traces, outputs, nominal, values):
            resolution[fit.name] = fit.resolution
            series[fit.name] = fit.series
            names.append(fit.name)
            rows.append(np.log(np.maximum(fit.before, 1e-300) / np.maximum(fit.after, 1e-300)))
            before[fit.name] = float(np.sqrt(np.mean(fit.before)))
            x_after[fit.name] = float(np.sqrt(np.mean(fit.after)))
            info[fit.name] = (fit.kind, fit.channel, fit.formula, "balances")
    gains = np.stack(rows)
    p_family = family_p_values(gains)
    evidence = {}
    signatures = []
    for name, g, p in zip(names, gains, p_family, strict=True):
        ev = Evidence(before[name], x_after[name], p_value_of_gains(g), int(g.size), float(p))
        evidence[name] = ev
        kind, channel, formula, source = info[name]
        signatures.append(
            Signature(
                kind=kind,
                channel=channel,
                formula=formula,
                closes=_closes(ev) if source == "outputs" else _removes(ev),
                excess_after=ev.x_after,
                p_family=ev.corrected_p(len(names)),
                passes=_passes(ev, len(names), resolution.get(name)),
                source=source,
                series=series.get(name, ()),
            )
        )
    # Passing ones first; among them the balances' (instantaneous: no bounce blurs them)
    # and a formula before ``other``, which only says that the remainder repeats with
    # the motion (the training cycles' mean predicts anything that does); then the one
    # that closes most.
    signatures.sort(
        key=lambda s: (not s.passes, s.source != "balances", s.kind == "other", -s.closes)
    )
    return signatures, fits, evidence


def _passes(ev: Evidence, tests: int, resolution: float | None) -> bool:
    """Evidence at the remainder's rate, and a gain that the noise's resolution allows.

    The model's outputs (``resolution`` None): the effects' own rule
    (``Evidence.accepted``). The balances have no floor to count a gap from (they can
    sit below 1 in motion), so their gain must exceed how well their noise unit is known
    (``balance.noise_resolution``, about 4 % with four recordings): a validation
    campaign with no effect had a drift term pass at p 0.001 for removing 0.3 % of the
    error, while a light weight's oiled guide removed 8.7 %.
    """
    if resolution is None:
        return ev.accepted(tests, REMAINDER_ALPHA)
    return ev.corrected_p(tests) <= REMAINDER_ALPHA and ev.gain >= resolution * ev.x_before


def _closes(ev: Evidence) -> float:
    """Share of the remainder above the noise (X − 1) that a signature closes, in [−1, 1].

    The noise is known to about a tenth, so a remainder near it can be closed "more than
    all the way"; 0 where there is nothing above the noise.
    """
    if ev.x_before <= 1.0:
        return 0.0
    return min(max((ev.x_before - ev.x_after) / (ev.x_before - 1.0), -1.0), 1.0)


def _removes(ev: Evidence) -> float:
    """Share of the balances' held-out mean square error that a signature removes.

    The balances' noise is their spread at rest, which the motion's can differ from by a
    tenth either way: the share of the error is what their fit says without it.
    """
    return 1.0 - (ev.x_after / ev.x_before) ** 2 if ev.x_before > 0 else 0.0


def remainder_of(
    traces: Sequence[Trace],
    outputs: Sequence[Outputs],
    nominal: StandParams,
    values: dict[str, float],
    x_base: float,
    where: Where | None = None,
    balances: bool = False,
    candidate: Candidate | None = None,
    named: bool = False,
) -> tuple[Remainder, int]:
    """The final model's remainder: judged, described, and its share of the baseline's gap.

    ``balances``: judge the force balances' variants too (where no effect is named).
    ``candidate``: the final model, whose own replicates the held-out error is held
    against (``adequacy``; it decides only where nothing is ``named``); None: not.
    Returns the remainder and the simulations spent.
    """
    # In the units of the model's miss (the held-out test pools each recording's channels
    # as a geometric mean, and a fit in noise units gave up the one the model met for the
    # one it missed most), each kind against the baseline's own terms refitted alone.
    signatures, fits, _ = judge_signatures(
        traces, outputs, nominal, values, balances, in_miss_units=True, beyond_baseline_terms=True
    )
    excess = heldout_excess(traces, outputs)
    own, sims = (
        own_excess(candidate, values, traces, nominal, excess)
        if candidate is not None
        else (None, 0)
    )
    passing = [s for s in signatures if s.passes]
    p_value = min((s.p_family for s in signatures), default=1.0)
    share = (excess - 1.0) / (x_base - 1.0) if x_base > 1.0 else 0.0
    remainder = Remainder(
        beyond_noise=bool(passing) or (own is not None and own.gross and not named),
        p_value=p_value,
        excess=excess,
        share_of_gap=min(max(share, 0.0), 1.0),
        where=where,
        signature=signatures,
        fits=fits,
        own=own,
    )
    return remainder, sims


def verdict(named: bool, remainder: Remainder) -> str:
    """One of ``VERDICTS`` from whether effects were named and what remains."""
    if named:
        return "partly_explained" if remainder.beyond_noise else "explained"
    return "unexplained" if remainder.beyond_noise else "baseline_adequate"
