"""Recordings a fitted model would make of itself: a parametric bootstrap's replicates.

Used where the diagnosis asks what the fitted model alone would give: the estimator's
bias and spread (``intervals``) and the held-out error a right model leaves
(``adequacy``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from sim.identify.fitting import Candidate
from sim.identify.traces import Trace
from sim.params import StandParams

__all__ = ["replicate_traces"]


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
    white noise at the recording's rest noise, keeps its lost samples, cycles and the
    held-out split, and the campaign's dial gauge scale.
    """
    runs = []
    for tr in traces:
        model = candidate.model(nominal, tr.mass_kg)
        res = model.run_batch(tr.x_m, tr.rate_hz, [candidate.variant(nominal, values)])
        runs.append((res.u_m[0] - res.u_m[0, 0], res.force_n[0]))
    out = []
    for _ in range(replicates):
        drawn = []
        for tr, (u, f) in zip(traces, runs, strict=True):
            u_r = u + rng.normal(0.0, tr.noise_u_m, u.size)
            f_r = f + rng.normal(0.0, tr.noise_force_n, f.size)
            drawn.append(
                dataclasses.replace(
                    tr,
                    u_m=np.where(tr.present, u_r, np.nan),
                    force_n=np.where(tr.present, f_r, np.nan),
                )
            )
        out.append(drawn)
    return out
