"""Screening: which effects could explain the baseline's residual (a score test).

Each effect's output change at a few probe magnitudes (its typical range), projected off
the baseline parameters' directions; the share of the baseline's residual that direction
explains orders the candidates and gives each refit one more start point. A few
simulations per effect (one batch each). The same test on top of an accepted effect (its
fit as the base) orders the candidates for a second one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from sim.effects import EFFECTS
from sim.identify.fitting import (
    Candidate,
    FitResult,
    channel_spread,
    scored_samples,
    simulate_values,
)
from sim.identify.heldout import Outputs
from sim.identify.side_by_side import side_by_side
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]


def outputs_of(
    candidate: Candidate, values: dict[str, float], traces: Sequence[Trace], nominal: StandParams
) -> list[Outputs]:
    """The candidate's recorded-channel outputs at one set of values, trace by trace.

    The traces run side by side (``side_by_side``): one set is too small a batch to
    fill the cores within a trace.
    """

    def trace_outputs(k: int, serial: bool) -> Outputs:
        u, f = simulate_values(candidate, [values], traces[k], nominal, serial=serial)
        return Outputs(u[0], f[0])

    return side_by_side(trace_outputs, [tr.samples for tr in traces])


def probe_values(effect: str, baseline: dict[str, float]) -> list[dict[str, float]]:
    """A few magnitudes across the plausible range (both signs where the range has both)."""
    info = EFFECTS[effect]
    probes = []
    for frac in (0.2, 0.5, 1.0):
        values = dict(baseline)
        for p in info.params:
            if not p.fit or p.form:  # a form parameter stays at its default
                continue
            if p.low < 0 < p.high:  # signed: probe both ends
                v = p.high * frac
            elif p.log:
                v = float(np.exp(np.log(p.low) + frac * (np.log(p.high) - np.log(p.low))))
            else:
                v = p.low + frac * (p.high - p.low)
            values[f"{effect}.{p.name}"] = v
        probes.append(values)
        signed = [p for p in info.params if p.fit and not p.form and p.low < 0 < p.high]
        if signed:
            neg = dict(values)
            for p in signed:
                neg[f"{effect}.{p.name}"] = p.low * frac
            probes.append(neg)
    return probes


def _stack(traces: Sequence[Trace], outs: Sequence[Outputs]) -> FloatArray:
    """Normalised training-sample vector of outputs (u and F per trace, every sample)."""
    parts = []
    for tr, o in zip(traces, outs, strict=True):
        idx = scored_samples(tr)
        for rec, sim in ((tr.u_m, o.u_m), (tr.force_n, o.force_n)):
            parts.append(sim[idx] / channel_spread(rec, idx))
    return np.concatenate(parts)


def _stacks_of(
    candidate: Candidate,
    value_sets: Sequence[dict[str, float]],
    traces: Sequence[Trace],
    nominal: StandParams,
) -> FloatArray:
    """``_stack`` of a candidate's outputs for many value sets, shape (sets, samples).

    One batch per trace (the sets fill the cores), simulating only what the score test
    compares.
    """
    parts = []
    for tr in traces:
        idx = scored_samples(tr)
        u, f = simulate_values(candidate, value_sets, tr, nominal, samples=idx)
        parts += [u / channel_spread(tr.u_m, idx), f / channel_spread(tr.force_n, idx)]
    return np.concatenate(parts, axis=1)


def screen(
    traces: Sequence[Trace],
    nominal: StandParams,
    base_fit: FitResult,
    base_out: Sequence[Outputs],
    effects: Sequence[str],
) -> tuple[dict[str, float], dict[str, dict[str, float]], int]:
    """Score test: share of the baseline residual each effect's direction explains."""
    y_rec = _stack(traces, [Outputs(t.u_m, t.force_n) for t in traces])
    y_base = _stack(traces, base_out)
    r = y_rec - y_base
    # Baseline parameters' directions (forward differences), to project off. Thresholds
    # and counts (``scan``) have no direction: the output is a step function of them.
    base_cand = base_fit.candidate
    bumps = []
    for p in base_cand.params:
        if p.scan:
            continue
        bumped = dict(base_fit.values)
        bumped[p.name] = base_fit.values[p.name] * 1.01 if base_fit.values[p.name] else 0.01
        bumps.append(bumped)
    jb = (_stacks_of(base_cand, bumps, traces, nominal) - y_base).T
    q, _ = np.linalg.qr(jb)
    r_perp = r - q @ (q.T @ r)
    r2 = float(r_perp @ r_perp) or 1e-300
    scores: dict[str, float] = {}
    best_probe: dict[str, dict[str, float]] = {}
    sims = len(bumps)
    for effect in effects:
        # On top of the effects the base fit already has (none for the baseline).
        cand = Candidate.build(*base_cand.effects, effect)
        best = 0.0
        probes = probe_values(effect, base_fit.values)
        changes = _stacks_of(cand, probes, traces, nominal) - y_base
        sims += len(probes)
        for values, change in zip(probes, changes, strict=True):
            d = change.copy()  # its own buffer: BLAS rounds by alignment (bit-identical)
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
