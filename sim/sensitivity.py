"""How fast two nearby runs drift apart: where a run is too violent to 'converge'.

In violent quick tests the weight is launched and bounces on the fibre; the time of each
snatch depends on the previous bounce, so tiny differences (a parameter in its tenth
digit, an integrator's rounding) can grow from bounce to bounce. Rather than claim
convergence there, measure it: run the model twice with the fibre stiffness perturbed by
a relative ``epsilon`` and report how the difference grows over time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.model import Model
from sim.params import StandParams

__all__ = ["Divergence", "nearby_run_divergence"]


@dataclass(frozen=True)
class Divergence:
    """Growth of the difference between two nearby runs.

    Attributes
    ----------
    t_s
        Time, s.
    difference_m
        Running maximum of |u₁ − u₂|, m.
    amplification
        Final difference over the difference at ``first_cycle_end_s``: ≈ 1 means errors
        stay put; ≫ 1 means the run amplifies any error from bounce to bounce, and a
        comparison of two such runs (or of a run with a recording) is only meaningful
        over the first cycles.
    """

    t_s: NDArray[np.float64]
    difference_m: NDArray[np.float64]
    amplification: float


def nearby_run_divergence(
    x_m: NDArray[np.float64],
    rate_hz: float,
    params: StandParams,
    first_cycle_end_s: float,
    epsilon: float = 1e-9,
) -> Divergence:
    """Run twice, stiffness perturbed by ``epsilon`` (relative); see Divergence."""
    a = Model(params).run(x_m, rate_hz)
    b = Model(params.with_(stiffness_n_m=params.stiffness_n_m * (1 + epsilon))).run(x_m, rate_hz)
    diff = np.maximum.accumulate(np.abs(a.u_m - b.u_m))
    first = diff[min(int(first_cycle_end_s * rate_hz), diff.size - 1)]
    floor = epsilon * params.preload_m * 1e-3  # below this the difference is rounding
    return Divergence(a.t_s, diff, float(diff[-1] / max(first, floor)))
