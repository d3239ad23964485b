"""The diagnosis: where the gap lies, which effects explain it, how far it shrinks, how sure.

The gap is measured on held-out cycles, in noise units. The stages, in order:

1. **Baseline** (``_baseline``): the stiffness, damping and friction scale (``fitting``).
2. **Screen** (``_screen``): a score test of every candidate effect (``screening``) orders
   them and gives each refit a start point.
3. **Refit** (``_refit_all``): every candidate (baseline parameters and the effect's
   together, from the best point of a grid over the effect's physical range, with points
   the recordings show directly) on the training cycles; the leader's form too.
4. **Judge** (``_best_baseline``, ``_name_effects``): the baseline gets the same chance
   (each candidate's baseline parameters alone); each candidate is judged against it on
   held-out cycles (``decide``): the best closure whose gain is evidence at the
   family-wise rate ``ALPHA`` is named, unless a signature of the remainder beats it
   (``naming.signature_rival``); those that do about as well are named beside it.
5. **Further effects** (``_further_effects``): on top of those named, the next best
   candidates are refitted with them and judged against them the same way, up to
   ``MAX_EFFECTS``, each also against the richer forms of those named.
6. **How sure** (``how_sure``): intervals of the final model's parameters and the gap
   (``intervals``), every recording fitted alone (``per_recording``), and the fibre's
   stiffness against the rate it is strained at (``dynamic_stiffness``).
7. **What remains** (``_what_remains``): a systematic remainder or none, and what it is
   like (``remainder``); the verdict joins it with the effects named.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from sim.effects import EFFECTS
from sim.identify.decide import Evidence, judge
from sim.identify.dynamic_stiffness import rate_dependence
from sim.identify.fitting import Candidate, FitResult, fit, weighed_by_miss
from sim.identify.heldout import (
    Outputs,
    bootstrap_confidence,
    channel_gap,
    cycle_improvements,
    heldout_error,
    heldout_excess,
    noise_floor,
)
from sim.identify.intervals import (
    BIAS_REPLICATES,
    GAP_METHOD,
    PARAMETER_METHOD,
    gap_intervals,
    parameter_intervals,
)
from sim.identify.naming import (
    MAX_EFFECTS,
    OnTop,
    further_effect,
    indistinguishable,
    ranking_of,
    signature_rival,
    strongest_accepted,
)
from sim.identify.per_recording import per_recording_report
from sim.identify.refitting import (
    Fitted,
    Progress,
    bound_params,
    closure,
    data_starts,
    effect_params,
    own_values,
    polish,
    refine_form,
    refit,
)
from sim.identify.remainder import Remainder, remainder_of, verdict
from sim.identify.report import AcceptedEffect, Diagnosis, RankedEffect
from sim.identify.screening import outputs_of, screen
from sim.identify.shooting import dial_slope
from sim.identify.side_by_side import in_lanes
from sim.identify.traces import Trace
from sim.identify.where import SimStates, where_the_gap_lies
from sim.params import StandParams

__all__ = ["diagnose", "how_sure"]


@dataclass
class _Run:
    """What every stage reads (the recordings, the nominal stand) and adds to (costs)."""

    traces: list[Trace]
    nominal: StandParams
    say: Progress
    timings: dict[str, float] = field(default_factory=dict)
    simulations: int = 0
    #: The traces as the final model was fitted (``weighed_by_miss``); None: ``traces``.
    fit_traces: list[Trace] | None = None

    @contextmanager
    def timed(self, key: str) -> Iterator[None]:
        """Adds the block's wall time to ``timings[key]``."""
        started = time.perf_counter()
        try:
            yield
        finally:
            self.timings[key] = self.timings.get(key, 0.0) + time.perf_counter() - started


@dataclass
class _Judged:
    """The first stages' answer: the best baseline, each candidate alone, the evidence."""

    base_fit: FitResult
    base_values: dict[str, float]
    base_out: list[Outputs]
    x_base: float
    refits: dict[str, Fitted]
    evidence: dict[str, Evidence]
    ranking: list[RankedEffect]


def diagnose(
    traces: Sequence[Trace],
    nominal: StandParams,
    candidates: Sequence[str] | None = None,
    progress: Progress | None = None,
) -> Diagnosis:
    """Diagnose a campaign of traces of one stand against the nominal parameters.

    ``candidates``: effect names to consider (default: every effect in ``EFFECTS``).
    """
    pool = list(candidates if candidates is not None else EFFECTS)
    # One dial gauge for the whole campaign: its scale against the drive, from all
    # traces, anchors every restart (``shooting.dial_slope``).
    slope = dial_slope(traces)
    run = _Run([dataclasses.replace(tr, dial_slope=slope) for tr in traces], nominal,
               progress or (lambda _msg: None))  # fmt: skip
    with run.timed("total"):
        judged = _judge_alone(run, pool)
        accepted, displaced, final, confidence = _name_effects(run, judged, pool)
        after_out = final.outputs if accepted else judged.base_out
        final_fit = (
            final.result if accepted
            else FitResult(judged.base_fit.candidate, judged.base_values, 0.0, 0)
        )  # fmt: skip
        run.say("how sure: intervals, and the parameters per recording")
        with run.timed("intervals"):
            sure = how_sure(
                run, final_fit, judged.base_values, accepted, judged.base_out, after_out
            )
        run.say("judging what remains")
        with run.timed("remainder"):
            remainder = _what_remains(run, after_out, final_fit, judged.x_base, accepted)
    return Diagnosis(
        effects=accepted,
        ranking=judged.ranking,
        where=where_the_gap_lies(run.traces, _states(run.traces, judged.base_out)),
        gap_before=channel_gap(run.traces, judged.base_out),
        gap_after=channel_gap(run.traces, after_out),
        baseline={k: final_fit.values[k] for k in judged.base_values},
        heldout_error_before=heldout_error(run.traces, judged.base_out),
        heldout_error_after=heldout_error(run.traces, after_out),
        noise_floor=noise_floor(run.traces),
        gap_closure=closure(judged.x_base, heldout_excess(run.traces, after_out), judged.x_base),
        confidence=confidence,
        timings_s=run.timings,
        simulations=run.simulations,
        outputs_before=judged.base_out,
        outputs_after=after_out,
        verdict=verdict(bool(accepted), remainder),
        remainder=remainder,
        displaced=displaced,
        **sure,
    )


def _judge_alone(run: _Run, pool: Sequence[str]) -> _Judged:
    """Stages 1–4: the baseline, the screening, every candidate refitted, the evidence."""
    base_fit, base_out = _baseline(run)
    scores, probes = _screen(run, base_fit, base_out, pool)
    order = sorted(pool, key=lambda e: -scores[e])
    refits = _refit_all(run, order, scores, probes, base_fit.values)
    base_values, base_out, x_base = _best_baseline(run, base_fit, base_out, refits)
    evidence = judge(run.traces, base_out, {e: f.outputs for e, f in refits.items()})
    ranking = ranking_of(order, scores, refits, evidence, x_base, run.traces)
    return _Judged(base_fit, base_values, base_out, x_base, refits, evidence, ranking)


def _baseline(run: _Run) -> tuple[FitResult, list[Outputs]]:
    """Stage 1: the baseline's stiffness, damping and friction scale."""
    run.say("fitting the baseline (stiffness, damping, friction scale)")
    with run.timed("baseline_fit"):
        base_fit = fit(Candidate.build(), run.traces, run.nominal)
        base_out = outputs_of(base_fit.candidate, base_fit.values, run.traces, run.nominal)
    run.simulations += base_fit.evaluations
    return base_fit, base_out


def _screen(
    run: _Run, base_fit: FitResult, base_out: list[Outputs], pool: Sequence[str]
) -> tuple[dict[str, float], dict[str, dict[str, float]]]:
    """Stage 2: every candidate's score test on the baseline, and its best probe."""
    run.say("screening the candidate effects")
    with run.timed("screening"):
        scores, probes, sims = screen(run.traces, run.nominal, base_fit, base_out, pool)
    run.simulations += sims
    return scores, probes


def _refit_all(
    run: _Run,
    order: Sequence[str],
    scores: dict[str, float],
    probes: dict[str, dict[str, float]],
    base_values: dict[str, float],
) -> dict[str, Fitted]:
    """Stage 3: every candidate refitted alone on the baseline, the leader's form too."""

    def refit_one(k: int) -> tuple[Fitted, float]:
        effect = order[k]
        run.say(f"refitting {effect} (screening score {scores[effect]:.3f})")
        started = time.perf_counter()
        probe = [probes[effect]] if effect in probes else []
        shown = data_starts(effect, run.traces, run.nominal, base_values)
        fitted = refit(candidates[k], run.traces, run.nominal, base_values, probe, shown)
        return fitted, time.perf_counter() - started

    candidates = [Candidate.build(effect) for effect in order]
    refits: dict[str, Fitted] = {}
    with run.timed("refits"):
        # Side by side (the numbers are those of one after the other); a refit's cost
        # grows with its parameters (a Jacobian is a batch of p + 1 sets).
        done = in_lanes(refit_one, [len(c.params) for c in candidates])
        for effect, (fitted, seconds) in zip(order, done, strict=True):
            refits[effect] = fitted
            run.timings[f"refit {effect}"] = seconds
            run.simulations += fitted.result.evaluations
        leader = min(refits, key=lambda e: refits[e].result.train_cost, default=None)
        if leader is not None:
            started = time.perf_counter()
            refits[leader], form_sims = refine_form(refits[leader], run.traces, run.nominal,
                                                    run.say)  # fmt: skip
            if form_sims:
                run.timings[f"form {leader}"] = time.perf_counter() - started
            run.simulations += form_sims
    return refits


def _best_baseline(
    run: _Run, base_fit: FitResult, base_out: list[Outputs], refits: dict[str, Fitted]
) -> tuple[dict[str, float], list[Outputs], float]:
    """Stage 4a: the baseline with the same chance as the candidates.

    Its training cost can favour parameters that held-out cycles do not (a violent
    segment's snatch timing pulls the damping), so a candidate whose refit merely moved
    the baseline's parameters would pose as the effect. Each candidate's baseline
    parameters alone are judged on the held-out cycles; the best baseline is the one
    every candidate must beat.
    """
    values, x_base = base_fit.values, heldout_excess(run.traces, base_out)
    with run.timed("baseline_check"):
        for fitted in refits.values():
            own = {p.name: fitted.result.values[p.name] for p in base_fit.candidate.params}
            outs = outputs_of(base_fit.candidate, own, run.traces, run.nominal)
            run.simulations += len(run.traces)
            excess = heldout_excess(run.traces, outs)
            if excess < x_base:
                values, base_out, x_base = own, outs, excess
    return values, base_out, x_base


def _name_effects(
    run: _Run, judged: _Judged, pool: Sequence[str]
) -> tuple[list[AcceptedEffect], dict[str, str], Fitted, float]:
    """Stages 4b and 5: the first effect, then further ones on top.

    Returns the named effects, those displaced (effect → signature kind), the final
    model's fit (where an effect is named) and the bootstrap confidence.
    """
    refits, evidence, traces = judged.refits, judged.evidence, run.traces
    displaced: dict[str, str] = {}
    chosen = strongest_accepted(judged.ranking, evidence, len(refits))
    best = chosen or (judged.ranking[0].effect if judged.ranking else None)
    confidence = 0.0
    if best is not None:
        gains = cycle_improvements(traces, judged.base_out, refits[best].outputs)
        confidence = bootstrap_confidence(gains)
    if chosen is not None:
        with run.timed("signature_check"):
            rival = signature_rival(traces, judged.base_out, run.nominal, judged.base_values,
                                    refits[chosen].outputs)  # fmt: skip
        if rival is not None:
            run.say(f"{chosen} does no better than a {rival} term: not named")
            displaced[chosen] = rival
    placeholder = Fitted(judged.base_fit, judged.base_out, judged.x_base)
    if best is None or best in displaced or not evidence[best].accepted(len(refits)):
        return [], displaced, placeholder, confidence
    run.say(f"polishing {best}")
    with run.timed("polish"):
        current = polish(refits[best], traces, run.nominal)
    run.simulations += current.result.evaluations
    first = AcceptedEffect(
        best,
        closure(judged.x_base, current.excess, judged.x_base),
        evidence[best].corrected_p(len(refits)),
        effect_params(best, current.result.values),
        bound_params(current.result, best),
        indistinguishable(best, refits, evidence, traces, len(refits)),
    )
    with run.timed("further_effects"):
        accepted, current = _further_effects(run, judged, pool, [first], current, displaced)
    return accepted, displaced, current, confidence


def _further_effects(
    run: _Run,
    judged: _Judged,
    pool: Sequence[str],
    accepted: list[AcceptedEffect],
    current: Fitted,
    displaced: dict[str, str],
) -> tuple[list[AcceptedEffect], Fitted]:
    """Stage 5: further effects, one at a time on top of those named (``MAX_EFFECTS``).

    Each is judged against the model before it and a signature of its remainder; one no
    better than a richer form of those named is set aside (``displaced``).
    """
    trained = {e: f.result.train_cost for e, f in judged.refits.items()}
    alone = {e: own_values(e, f.result.values) for e, f in judged.refits.items()}
    set_aside: list[str] = []  # passed, but no better than a richer form
    memo: OnTop | None = None  # a set-aside try leaves the model: its work stands
    while len(accepted) + len(set_aside) < MAX_EFFECTS:  # each try: ~10 s of refits
        named = tuple(a.effect for a in accepted)
        memo = memo if memo is not None and memo.named == named else OnTop(named)
        found, sims = further_effect(
            named, current, trained, alone, judged.base_fit.train_cost,
            [e for e in pool if e not in set_aside], run.traces, run.nominal, judged.x_base,
            run.say, memo,
        )  # fmt: skip
        run.simulations += sims
        if found is None:
            break
        if found.line is None or found.fitted is None:  # a form mismatch of those named
            run.say(f"{found.effect} does no better than a {found.rival} term: not named")
            displaced[found.effect] = str(found.rival)
            set_aside.append(found.effect)
            continue
        accepted.append(found.line)
        run.fit_traces = weighed_by_miss(run.traces, current.outputs)  # as it was fitted
        current = found.fitted
    return accepted, current


def how_sure(
    run: _Run,
    final: FitResult,
    base_values: dict[str, float],
    accepted: Sequence[AcceptedEffect],
    before: Sequence[Outputs],
    after: Sequence[Outputs],
) -> dict[str, Any]:
    """Stage 6: intervals of the final model's parameters and the gap; per-recording fits.

    The named effects' parameters are as the final model (all together) has them.
    """
    # In the units the final model was fitted in (a further effect's: ``weighed_by_miss``),
    # so that its values are the least cost the intervals' refits start from.
    traces, nominal = run.traces, run.nominal
    sure = parameter_intervals(
        final.candidate, final.values, run.fit_traces or traces, nominal,
        replicates=BIAS_REPLICATES,
    )  # fmt: skip
    for a in accepted:
        prefix = f"{a.effect}."
        a.params = effect_params(a.effect, final.values)
        a.intervals = {
            k[len(prefix) :]: v for k, v in sure.intervals.items() if k.startswith(prefix)
        }
        a.at_bound = bound_params(final, a.effect)
        a.reaches_bound = [k[len(prefix) :] for k in sure.reaches_bound if k.startswith(prefix)]
    gaps, gap_closure = gap_intervals(traces, before, after)
    table, agree, alone, sims = per_recording_report(
        final.candidate, final.values, base_values, traces, nominal
    )
    run.simulations += sure.simulations + sims
    # The fibre's stiffness against its strain rate, off the law in the recordings.
    with run.timed("dynamic_stiffness"):
        rate = {"baseline_alone": rate_dependence(traces, nominal, base_values, before)}
        if accepted:
            rate["final"] = rate_dependence(
                traces, nominal, final.values, after, rate["baseline_alone"], named=True
            )
    return {
        "baseline_intervals": {k: v for k, v in sure.intervals.items() if k in base_values},
        "baseline_reaches_bound": [k for k in sure.reaches_bound if k in base_values],
        "gap_closure_interval": gap_closure,
        "gap_intervals": gaps,
        "interval_method": f"{PARAMETER_METHOD}; {GAP_METHOD}",
        "per_recording": table,
        "consistency": agree,
        "baseline_consistency": alone,
        "dynamic_stiffness": {k: v.to_dict() for k, v in rate.items() if v is not None},
    }


def _states(traces: Sequence[Trace], outputs: Sequence[Outputs]) -> list[SimStates]:
    return [
        SimStates.of(o.u_m, o.force_n, tr.rate_hz) for tr, o in zip(traces, outputs, strict=True)
    ]


def _what_remains(
    run: _Run,
    after: Sequence[Outputs],
    final: FitResult,
    x_base: float,
    accepted: Sequence[AcceptedEffect],
) -> Remainder:
    """Stage 7: the remainder after the named effects, and what it is like."""
    where = where_the_gap_lies(run.traces, _states(run.traces, after))
    remainder, sims = remainder_of(run.traces, after, run.nominal, final.values, x_base,
                                   where, balances=not accepted, candidate=final.candidate,
                                   named=bool(accepted))  # fmt: skip
    run.simulations += sims
    return remainder
