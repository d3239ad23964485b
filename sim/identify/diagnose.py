"""The diagnosis: where the gap lies, which effect explains it, how far it shrinks.

The gap is measured on held-out data.

1. Fit the baseline's stiffness, damping and friction scale (``fitting``).
2. Attribute its residual (``where``).
3. Screen every candidate effect with a score test: its output change at probe
   magnitudes, projected off the baseline parameters' directions, and how much of the
   residual that direction explains (a few simulations per effect).
4. Refit the best few candidates fully (baseline parameters and the effect's together,
   multi-start) on the training cycles.
5. Judge each on the held-out cycles: its error against the fitted baseline's and the
   noise floor. An effect is chosen only if it closes a clear part of the gap, beats the
   baseline on held-out cycles with bootstrap confidence, and beats the runner-up; else
   the answer is ``none``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.effects import EFFECTS
from sim.identify.fitting import (
    Candidate,
    FitResult,
    effect_grid_start,
    fit,
    simulate_values,
)
from sim.identify.heldout import (
    Outputs,
    bootstrap_confidence,
    channel_gap,
    cycle_improvements,
    heldout_error,
    heldout_excess,
    noise_floor,
)
from sim.identify.traces import Trace
from sim.identify.where import SimStates, Where, where_the_gap_lies
from sim.params import StandParams

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)

#: Candidates are judged by their held-out error in noise units (``heldout_excess``;
#: 1 = a perfect model). An effect must remove at least this share of the baseline's…
MIN_RELATIVE_GAIN = 0.05
#: …and this share of the part of it above the noise (the gap closure)…
MIN_GAP_CLOSURE = 0.3
#: …by at least this many noise units (an improvement smaller than the noise's own
#: jitter is not evidence)…
MIN_GAIN_OVER_NOISE = 0.1
#: …with this bootstrap confidence over held-out cycles.
MIN_CONFIDENCE = 0.95
#: Refit every candidate whose screening score reaches this share of the best one's (0:
#: refit all; the screening only orders them and gives their start values). Screening
#: alone missed effects whose output change is far from linear in their magnitude
#: (pulley jump, string modes), so every candidate is refitted.
REFIT_SHARE = 0.0
#: Optimiser evaluations per candidate refit (each a batch of simulations).
REFIT_EVALUATIONS = 15
#: Further optimiser evaluations for the chosen effect, whose fit says how far the gap
#: shrinks (the ranking needs only the short refits).
POLISH_EVALUATIONS = 40
#: Held-out error penalty per extra fitted parameter (relative), to prefer simple effects.
PARAM_PENALTY = 0.003

Progress = Callable[[str], None]


@dataclass
class RankedEffect:
    """One candidate's line in the ranking."""

    effect: str
    #: Share of the baseline residual the screening probe explained.
    screening: float
    #: Held-out gap closure after the penalty; None when the candidate was not refitted.
    score: float | None = None
    #: Held-out RMS of the channels' NRMSE.
    heldout_error: float | None = None
    #: Held-out error in noise units (what the score is made of; 1 = perfect).
    heldout_excess: float | None = None
    params: dict[str, float] = field(default_factory=dict)
    #: Fitted parameters that ended on a bound of their physical range: the effect may be
    #: larger than the range allows, or of another form.
    at_bound: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """JSON keys effect, score, heldout_error, heldout_excess, screening, params, at_bound."""
        return {
            "effect": self.effect,
            "score": self.score,
            "heldout_error": self.heldout_error,
            "heldout_excess": self.heldout_excess,
            "screening": self.screening,
            "params": self.params,
            "at_bound": self.at_bound,
        }


#: Per channel (``u``, ``F``): R, psi and NRMSE on the held-out samples.
ChannelGap = dict[str, dict[str, float]]


@dataclass
class Diagnosis:
    """The answer: the typed report the CLI and the HTML page both read (``to_dict``: JSON)."""

    effect: str
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
    #: The least held-out gap closure an effect needed to be the answer.
    closure_needed: float = MIN_GAP_CLOSURE
    timings_s: dict[str, float] = field(default_factory=dict)
    simulations: int = 0
    outputs_before: list[Outputs] = field(default_factory=list, repr=False)
    outputs_after: list[Outputs] = field(default_factory=list, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON keys: effect, ranking, where, gap_before, gap_after, and details."""
        return {
            "effect": self.effect,
            "ranking": [r.to_dict() for r in self.ranking],
            "where": self.where.to_dict(),
            "gap_before": self.gap_before,
            "gap_after": self.gap_after,
            "baseline_fit": self.baseline,
            "heldout_error_before": self.heldout_error_before,
            "heldout_error_after": self.heldout_error_after,
            "noise_floor": self.noise_floor,
            "gap_closure": self.gap_closure,
            "closure_needed": self.closure_needed,
            "confidence": self.confidence,
            "simulations": self.simulations,
            "timings_s": self.timings_s,
        }


def _outputs(
    candidate: Candidate, values: dict[str, float], traces: Sequence[Trace], nominal: StandParams
) -> list[Outputs]:
    outs = []
    for tr in traces:
        u, f = simulate_values(candidate, [values], tr, nominal)
        outs.append(Outputs(u[0], f[0]))
    return outs


def _probe_values(effect: str, baseline: dict[str, float]) -> list[dict[str, float]]:
    """A few magnitudes across the plausible range (both signs where the range has both)."""
    info = EFFECTS[effect]
    probes = []
    for frac in (0.2, 0.5, 1.0):
        values = dict(baseline)
        for p in info.params:
            if not p.fit:
                continue
            if p.low < 0 < p.high:  # signed: probe both ends
                v = p.high * frac
            elif p.log:
                v = float(np.exp(np.log(p.low) + frac * (np.log(p.high) - np.log(p.low))))
            else:
                v = p.low + frac * (p.high - p.low)
            values[f"{effect}.{p.name}"] = v
        probes.append(values)
        signed = [p for p in info.params if p.fit and p.low < 0 < p.high]
        if signed:
            neg = dict(values)
            for p in signed:
                neg[f"{effect}.{p.name}"] = p.low * frac
            probes.append(neg)
    return probes


def _stack(traces: Sequence[Trace], outs: Sequence[Outputs]) -> FloatArray:
    """Normalised training-sample vector of outputs (u and F per trace)."""
    parts = []
    for tr, o in zip(traces, outs, strict=True):
        idx = np.flatnonzero(tr.present & tr.train)[::4]
        for rec, sim in ((tr.u_m, o.u_m), (tr.force_n, o.force_n)):
            spread = float(np.linalg.norm(rec[idx] - rec[idx].mean())) or 1.0
            parts.append(sim[idx] / spread)
    return np.concatenate(parts)


def screen(
    traces: Sequence[Trace], nominal: StandParams, base_fit: FitResult, base_out: Sequence[Outputs]
) -> tuple[dict[str, float], dict[str, dict[str, float]], int]:
    """Score test: share of the baseline residual each effect's direction explains."""
    y_rec = _stack(traces, [Outputs(t.u_m, t.force_n) for t in traces])
    y_base = _stack(traces, base_out)
    r = y_rec - y_base
    # Baseline parameters' directions (forward differences), to project off.
    base_cand = base_fit.candidate
    cols = []
    for p in base_cand.params:
        bumped = dict(base_fit.values)
        bumped[p.name] = base_fit.values[p.name] * 1.01 if base_fit.values[p.name] else 0.01
        cols.append(_stack(traces, _outputs(base_cand, bumped, traces, nominal)) - y_base)
    jb = np.stack(cols, axis=1)
    q, _ = np.linalg.qr(jb)
    r_perp = r - q @ (q.T @ r)
    r2 = float(r_perp @ r_perp) or 1e-300
    scores: dict[str, float] = {}
    best_probe: dict[str, dict[str, float]] = {}
    sims = len(cols)
    for effect in EFFECTS:
        cand = Candidate.build(effect)
        best = 0.0
        for values in _probe_values(effect, base_fit.values):
            d = _stack(traces, _outputs(cand, values, traces, nominal)) - y_base
            sims += 1
            d_perp = d - q @ (q.T @ d)
            denom = float(d_perp @ d_perp)
            a = float(d_perp @ r_perp) / denom if denom > 0 else 0.0
            # Only a positive multiple of the probe's change is the effect itself;
            # a multiple far beyond the probe is not a small-effect explanation.
            explained = (a * a * denom / r2) if 0 < a <= 3.0 else 0.0
            if explained > best:
                best = explained
                best_probe[effect] = values
        scores[effect] = best
    return scores, best_probe, sims


def diagnose(
    traces: Sequence[Trace],
    nominal: StandParams,
    refit_top: int = 9,
    progress: Progress | None = None,
) -> Diagnosis:
    """Diagnose a campaign of traces of one stand against the nominal parameters."""
    say = progress or (lambda _msg: None)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    say("fitting the baseline (stiffness, damping, friction scale)")
    base_fit = fit(Candidate.build(None), traces, nominal)
    base_out = _outputs(base_fit.candidate, base_fit.values, traces, nominal)
    timings["baseline_fit"] = time.perf_counter() - t0
    sims = base_fit.evaluations

    t1 = time.perf_counter()
    say("screening the candidate effects")
    scores, probes, screen_sims = screen(traces, nominal, base_fit, base_out)
    sims += screen_sims
    timings["screening"] = time.perf_counter() - t1

    x_base = heldout_excess(traces, base_out)
    order = sorted(scores, key=lambda e: -scores[e])
    refits: dict[str, tuple[FitResult, list[Outputs], float]] = {}
    t2 = time.perf_counter()
    # Refit the leader and whoever the screening cannot tell from it.
    contenders = [e for e in order[:refit_top] if scores[e] >= REFIT_SHARE * scores[order[0]]]
    for effect in contenders:
        say(f"refitting {effect} (screening score {scores[effect]:.3f})")
        started = time.perf_counter()
        cand = Candidate.build(effect)
        probe = [probes[effect]] if effect in probes else []
        start = effect_grid_start(cand, traces, nominal, base_fit.values, probe)
        res = fit(
            cand,
            traces,
            nominal,
            baseline=start,
            single_start=True,
            max_nfev=REFIT_EVALUATIONS,
        )
        timings[f"refit {effect}"] = time.perf_counter() - started
        sims += res.evaluations
        outs = _outputs(res.candidate, res.values, traces, nominal)
        refits[effect] = (res, outs, heldout_excess(traces, outs))
    timings["refits"] = time.perf_counter() - t2

    # The baseline gets the same chance as the candidates. Its training cost can favour
    # parameters that held-out cycles do not (a violent segment's snatch timing pulls the
    # damping), so a candidate whose refit merely moved the baseline's parameters would
    # pose as the effect. Each candidate's baseline parameters alone are judged on the
    # held-out cycles; the best baseline is the one every candidate must beat.
    started = time.perf_counter()
    base_values = base_fit.values
    for res, _, _ in refits.values():
        values = {p.name: res.values[p.name] for p in base_fit.candidate.params}
        outs = _outputs(base_fit.candidate, values, traces, nominal)
        sims += len(traces)
        excess = heldout_excess(traces, outs)
        if excess < x_base:
            base_values, base_out, x_base = values, outs, excess
    if base_values is not base_fit.values:
        log.info("baseline from a candidate's parameters: held-out %.6g", x_base)
    timings["baseline_check"] = time.perf_counter() - started

    # The fitted baseline as the fit saw it (segments from measured states): an
    # open-loop run of a chaotic light-weight recording would attribute chaos.
    states = [
        SimStates(o.u_m, o.force_n, np.gradient(o.u_m, 1.0 / tr.rate_hz))
        for tr, o in zip(traces, base_out, strict=True)
    ]
    where = where_the_gap_lies(traces, states)

    ranking: list[RankedEffect] = []
    for effect in order:
        line = RankedEffect(effect, screening=scores[effect])
        if effect in refits:
            res, outs, x_aug = refits[effect]
            penalised = x_aug * (1 + PARAM_PENALTY * (len(res.candidate.params) - 3))
            # Gap closure; clipped below at −1 (far worse than the baseline is just worse).
            line.score = max(-1.0, (x_base - penalised) / max(x_base - 1.0, 1e-12))
            line.heldout_error = heldout_error(traces, outs)
            line.heldout_excess = x_aug
            line.params = _effect_params(effect, res.values)
            line.at_bound = _at_bound(res)
        ranking.append(line)
    ranking.sort(key=lambda r: (r.score is None, -(r.score or 0.0), -r.screening))

    chosen = "none"
    confidence = 0.0
    after_out = base_out
    best = ranking[0]
    if best.score is not None:
        _, outs, x_aug = refits[best.effect]
        gains = cycle_improvements(traces, base_out, outs)
        confidence = bootstrap_confidence(gains)
        relative = (x_base - x_aug) / x_base if x_base > 0 else 0.0
        log.info(
            "best %s: closure %.3f, relative %.3f, confidence %.3f",
            best.effect,
            best.score,
            relative,
            confidence,
        )
        if (
            best.score >= MIN_GAP_CLOSURE
            and relative >= MIN_RELATIVE_GAIN
            and x_base - x_aug >= MIN_GAIN_OVER_NOISE
            and confidence >= MIN_CONFIDENCE
        ):
            chosen = best.effect
            say(f"polishing {chosen}")
            started = time.perf_counter()
            res = refits[chosen][0]
            polished = fit(
                res.candidate,
                traces,
                nominal,
                baseline=res.values,
                single_start=True,
                max_nfev=POLISH_EVALUATIONS,
            )
            sims += polished.evaluations
            timings["polish"] = time.perf_counter() - started
            # Judged on the training cycles only; the held-out ones then say how far.
            if polished.train_cost < res.train_cost:
                outs = _outputs(polished.candidate, polished.values, traces, nominal)
                best.params = _effect_params(chosen, polished.values)
                best.at_bound = _at_bound(polished)
            after_out = outs
    x_after = heldout_excess(traces, after_out)
    timings["total"] = time.perf_counter() - t0
    return Diagnosis(
        effect=chosen,
        ranking=ranking,
        where=where,
        gap_before=channel_gap(traces, base_out),
        gap_after=channel_gap(traces, after_out),
        baseline=base_values,
        heldout_error_before=heldout_error(traces, base_out),
        heldout_error_after=heldout_error(traces, after_out),
        noise_floor=noise_floor(traces),
        gap_closure=(x_base - x_after) / max(x_base - 1.0, 1e-12),
        confidence=confidence,
        timings_s=timings,
        simulations=sims,
        outputs_before=base_out,
        outputs_after=after_out,
    )


def _effect_params(effect: str, values: dict[str, float]) -> dict[str, float]:
    prefix = f"{effect}."
    return {k[len(prefix) :]: v for k, v in values.items() if k.startswith(prefix)}


def _at_bound(res: FitResult) -> list[str]:
    """The effect's parameters (names without the effect prefix) that ended on a bound."""
    prefix = f"{res.candidate.effect}."
    return [
        p.name[len(prefix) :]
        for p in res.candidate.params
        if p.name.startswith(prefix) and p.at_bound(res.values[p.name])
    ]
