"""The start grid's least-cost point, found with bounds instead of every simulation."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sim.checks.check import CaseSpec, make_campaign
from sim.config import default_config
from sim.identify.fitting import Candidate, Objective, effect_grid_start, fit, grid_axis
from sim.identify.least_cost import FloatArray, TraceCost, least_cost_point
from sim.identify.shooting import dial_slope


class _Table:
    """Per-trace costs looked up by point index (the point's only coordinate)."""

    def __init__(self, costs: np.ndarray) -> None:
        self.costs = costs  # (traces, points)
        self.scored = 0  # point-traces asked for

    def on(self, k: int) -> TraceCost:
        def cost(zs: FloatArray) -> FloatArray:
            self.scored += len(zs)
            return np.asarray(self.costs[k, zs[:, 0].astype(int)], dtype=np.float64)

        return cost


def _points(n: int) -> np.ndarray:
    return np.arange(n, dtype=np.float64)[:, None]


@pytest.mark.parametrize("seed", range(40))
def test_the_bounded_search_finds_the_plain_grids_point(seed: int) -> None:
    rng = np.random.default_rng(seed)
    traces, n = int(rng.integers(1, 5)), int(rng.integers(2, 80))
    costs = rng.gamma(0.5, 1.0, (traces, n))
    if seed % 2 == 0:  # exact ties, as where an effect's parameter does nothing: copies
        costs = np.tile(costs[:, : max(1, n // 3)], 3)  # of the best beside the leaders
        n = costs.shape[1]
    table = _Table(costs)
    lead = [int(i) for i in rng.choice(n, size=min(n, seed % 3), replace=False)]
    sizes = [int(s) for s in rng.integers(100, 10_000, traces)]
    got = least_cost_point([table.on(k) for k in range(traces)], sizes, _points(n), lead)
    assert got == int(np.argmin(costs.sum(axis=0)))  # ties: the lower index, as argmin


def test_points_far_above_the_best_stop_after_the_first_trace() -> None:
    # Three good points among a hundred poor ones: the poor ones' first trace alone
    # exceeds the best total, so they are scored on one trace of four.
    costs = np.full((4, 103), 10.0)
    costs[:, 100:] = [[1.0], [1.0], [1.0], [0.5]] * np.array([1.0, 0.9, 1.1])
    table = _Table(costs)
    got = least_cost_point([table.on(k) for k in range(4)], [1, 2, 3, 4], _points(103))
    assert got == 101
    assert table.scored <= 103 + 3 * 3


def test_a_real_grid_gets_the_plain_grids_start_for_fewer_simulations() -> None:
    # A light-weight campaign of the check (seed 1) with a withheld Maxwell branch: the
    # grid start is the point the plain grid scores best, for fewer simulated samples.
    stand = default_config()
    traces, _, _ = make_campaign(
        stand, "fibre_viscoelastic", 3.096, CaseSpec("fibre_viscoelastic", 3.096, 0, 1).rng()
    )
    slope = dial_slope(traces)
    traces = [dataclasses.replace(tr, dial_slope=slope) for tr in traces]
    nominal = stand.stand_params("final", 3.096)
    base = fit(Candidate.build(), traces, nominal)
    cand = Candidate.build("fibre_viscoelastic")
    start = effect_grid_start(cand, traces, nominal, base.values)

    own = cand.params[len(base.values) :]
    axes = np.meshgrid(*[grid_axis(p, 5) for p in own], indexing="ij")
    grid = np.stack([a.ravel() for a in axes], axis=1)
    fixed = [p.to_internal(base.values[p.name]) for p in cand.params[: len(base.values)]]
    points = np.hstack([np.tile(fixed, (len(grid), 1)), grid])
    plain = Objective(cand, traces, nominal)
    best = points[int(np.argmin(np.sum(plain.residuals_batch(points) ** 2, axis=1)))]
    assert cand.natural(best) == start
