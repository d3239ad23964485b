"""Errors on held-out data, the noise floor, and whether an improvement is significant."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from recordings.diagnosis.traces import Trace
from recordings.metrics import channel_metrics

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Outputs:
    """A model's recorded-channel outputs for one trace."""

    u_m: FloatArray
    force_n: FloatArray


def _test_parts(trace: Trace, out: Outputs) -> list[tuple[FloatArray, FloatArray, float]]:
    idx = trace.test
    parts = []
    for rec, sim, noise in (
        (trace.u_m, out.u_m, trace.noise_u_m),
        (trace.force_n, out.force_n, trace.noise_force_n),
    ):
        parts.append((rec[idx], sim[idx], noise))
    return parts


def heldout_error(traces: Sequence[Trace], outputs: Sequence[Outputs]) -> float:
    """RMS over traces and channels of the held-out NRMSE."""
    errors = []
    for tr, out in zip(traces, outputs, strict=True):
        for rec, sim, _ in _test_parts(tr, out):
            spread = float(np.linalg.norm(rec - rec.mean())) or 1.0
            errors.append(float(np.linalg.norm(sim - rec)) / spread)
    return float(np.sqrt(np.mean(np.square(errors))))


def noise_floor(traces: Sequence[Trace]) -> float:
    """The held-out error a perfect model would still show: sensor noise alone."""
    errors = []
    for tr in traces:
        idx = tr.test
        for rec, noise in ((tr.u_m[idx], tr.noise_u_m), (tr.force_n[idx], tr.noise_force_n)):
            spread = float(np.linalg.norm(rec - rec.mean())) or 1.0
            errors.append(noise * np.sqrt(rec.size) / spread)
    return float(np.sqrt(np.mean(np.square(errors))))


def channel_gap(traces: Sequence[Trace], outputs: Sequence[Outputs]) -> dict[str, dict[str, float]]:
    """R, ψ and NRMSE per channel over all held-out samples (traces concatenated)."""
    gap = {}
    for k, name in enumerate(("u", "F")):
        rec = np.concatenate(
            [_test_parts(t, o)[k][0] for t, o in zip(traces, outputs, strict=True)]
        )
        sim = np.concatenate(
            [_test_parts(t, o)[k][1] for t, o in zip(traces, outputs, strict=True)]
        )
        m = channel_metrics(rec, sim)
        gap[name] = {"R": m.R, "psi": m.psi, "nrmse": m.nrmse}
    return gap


def cycle_improvements(
    traces: Sequence[Trace], before: Sequence[Outputs], after: Sequence[Outputs]
) -> FloatArray:
    """Per held-out cycle: drop in normalised squared error (positive = better after)."""
    gains = []
    for tr, b, a in zip(traces, before, after, strict=True):
        idx = tr.test
        spreads = []
        for rec in (tr.u_m, tr.force_n):
            spreads.append(float(np.linalg.norm(rec[idx] - rec[idx].mean())) or 1.0)
        cycles = np.unique(tr.cycle[idx])
        for c in cycles:
            sel = idx & (tr.cycle == c)
            total = 0.0
            for rec, sb, sa, spread in (
                (tr.u_m, b.u_m, a.u_m, spreads[0]),
                (tr.force_n, b.force_n, a.force_n, spreads[1]),
            ):
                eb = np.sum((sb[sel] - rec[sel]) ** 2)
                ea = np.sum((sa[sel] - rec[sel]) ** 2)
                total += float(eb - ea) / spread**2
            gains.append(total)
    return np.asarray(gains)


def bootstrap_confidence(gains: FloatArray, rounds: int = 2000, seed: int = 0) -> float:
    """Share of bootstrap resamples (over whole cycles) in which the total gain is > 0."""
    if gains.size == 0:
        return 0.0
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, gains.size, size=(rounds, gains.size))
    return float(np.mean(gains[picks].sum(axis=1) > 0))
