"""The least-cost point of a start grid, without scoring every point on every trace.

A fit's cost is a sum over traces of sums of squares, so a point's cost on some of the
traces bounds its total from below. Once that partial cost exceeds the total of a point
already scored in full, the point cannot be the grid's best and its other traces need
not run (branch and bound). The answer is the plain grid's: the same point (the sums'
rounding aside), ties to the lower index. Unlike racing on part of the samples (which
dropped a skew's basin that shows only over a whole recording), nothing is dropped on a
guess.

Measured on three validation campaigns' grids (docs/diagnosis.md, "Time"): the pulley
inertia's and the Maxwell branch's grids need 0.4–0.6 of the simulated samples, the
pulley jump's 0.7–0.8 (its points mostly barely move the cost).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
#: Costs of many parameter vectors (sets, params) on one trace: shape (sets,).
TraceCost = Callable[[FloatArray], FloatArray]

#: Points scored in full after the first trace (its best few) to set the bar, beside the
#: ``lead`` points the caller knows to be good.
LEADERS = 2


def least_cost_point(
    trace_costs: Sequence[TraceCost],
    sizes: Sequence[int],
    points: FloatArray,
    lead: Sequence[int] = (),
) -> int:
    """Index of the point (row of ``points``) with the least cost summed over the traces.

    ``sizes``: each trace's simulated length (the cheapest runs first, to prune early).
    ``lead``: points to score in full first (e.g. starts the recordings show), whose best
    total is the first bar.
    """
    n = len(points)
    order = sorted(range(len(trace_costs)), key=lambda k: sizes[k])
    partial = np.asarray(trace_costs[order[0]](points), dtype=np.float64).copy()
    leaders = list(dict.fromkeys([*lead, *(int(i) for i in np.argsort(partial)[:LEADERS])]))
    total = np.full(n, np.inf)
    total[leaders] = partial[leaders]
    for k in order[1:]:
        total[leaders] += trace_costs[k](points[leaders])
    bar = float(total[leaders].min())
    # ``<=``: a point tied with the bar stays, so ties still go to the lower index.
    rest = np.setdiff1d(np.flatnonzero(partial <= bar), leaders)
    for k in order[1:]:
        if rest.size == 0:
            break
        partial[rest] += trace_costs[k](points[rest])
        rest = rest[partial[rest] <= bar]
    total[rest] = partial[rest]
    return int(np.argmin(total))
