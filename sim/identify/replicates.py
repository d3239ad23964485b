"""Recordings a fitted model would make of itself: a parametric bootstrap's replicates.

Used where the diagnosis asks what the fitted model alone would give: the estimator's
bias and spread (``intervals``) and the held-out error a right model leaves
(``adequacy``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from sim.identify.fitting import Candidate
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]

__all__ = ["reading_step", "replicate_traces"]

#: Steps between a quantised channel's readings are whole counts to this share of one.
ON_GRID = 1e-3


def replicate_traces(
    candidate: Candidate,
    values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
    rng: np.random.Generator,
    replicates: int,
) -> list[list[Trace]]:
    """Recordings the fitted model would make: its outputs plus each gauge's noise.

    The fitted model runs open loop on each recording's drive; every replicate adds new
    white noise at the recording's rest noise, reads it in the recording's own counts
    (``reading_step``), keeps its lost samples, cycles and the held-out split, and the
    campaign's dial gauge scale. The counts matter where the noise is below one: a dial
    gauge at rest that reads one count throughout has no rest noise, yet in motion its
    reading is off by up to half a count.
    """
    steps = [(reading_step(tr.u_m), reading_step(tr.force_n)) for tr in traces]
    runs = []
    for tr in traces:
        model = candidate.model(nominal, tr.mass_kg)
        res = model.run_batch(tr.x_m, tr.rate_hz, [candidate.variant(nominal, values)])
        runs.append((res.u_m[0] - res.u_m[0, 0], res.force_n[0]))
    out = []
    for _ in range(replicates):
        drawn = []
        for tr, (u, f), (step_u, step_f) in zip(traces, runs, steps, strict=True):
            u_r = _counts(u + rng.normal(0.0, tr.noise_u_m, u.size), step_u)
            f_r = _counts(f + rng.normal(0.0, tr.noise_force_n, f.size), step_f)
            drawn.append(
                dataclasses.replace(
                    tr,
                    u_m=np.where(tr.present, u_r, np.nan),
                    force_n=np.where(tr.present, f_r, np.nan),
                )
            )
        out.append(drawn)
    return out


def reading_step(values: FloatArray) -> float:
    """A quantised channel's count (the least step between its readings), 0 if it has none.

    A channel is quantised when every step between its successive readings is a whole
    number of its least non-zero step (to ``ON_GRID``); a channel in floating point
    (an already scaled or filtered one) has steps of every size.
    """
    diffs = np.abs(np.diff(values[np.isfinite(values)]))
    moves = diffs[diffs > 0.0]
    if moves.size < 2:
        return 0.0
    step = float(moves.min())
    if step < 1e-9 * float(moves.max()):
        return 0.0
    counts = moves / step
    return step if bool(np.all(np.abs(counts - np.round(counts)) <= ON_GRID * counts)) else 0.0


def _counts(values: FloatArray, step: float) -> FloatArray:
    return np.round(values / step) * step if step > 0.0 else values
