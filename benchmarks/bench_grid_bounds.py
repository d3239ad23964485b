"""Benchmark: every candidate's start grid, scored plainly and by bounds, side by side.

For one campaign (a validation case's recordings with ``--case DIR``, else a drawn
campaign of the check), the baseline is fitted once; then, for each candidate effect,
its start grid (``fitting.effect_grid_points``, without the extra points) is scored in
full (every point on every trace: numpy's argmin of the summed costs) and by
``least_cost_point``, alternately for ``--rounds`` rounds. Prints per candidate the
grid's size, the share of the plain grid's simulated samples the bounds needed, the best
time of each, and whether both chose the same point.

Run: ``.venv/bin/python benchmarks/bench_grid_bounds.py [--case ../shared/validation/val_02]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from collections.abc import Sequence
from functools import partial
from pathlib import Path

import numpy as np

from labstand.campaigns import trace_of
from recordings import open_recording
from sim.checks.check import CaseSpec, make_campaign
from sim.config import default_config, load_config
from sim.effects import EFFECTS
from sim.identify.fitting import Candidate, effect_grid_points, fit, trace_costs
from sim.identify.least_cost import FloatArray, TraceCost, least_cost_point
from sim.identify.shooting import dial_slope
from sim.identify.traces import Trace
from sim.params import StandParams


def load(case: Path | None) -> tuple[list[Trace], StandParams]:
    if case is None:
        stand = default_config()
        spec = CaseSpec("fibre_viscoelastic", 8.131, 0, 1)
        traces, _, _ = make_campaign(stand, spec.truth, spec.mass_kg, spec.rng())
        nominal = stand.stand_params("final", spec.mass_kg)
    else:
        mass = json.loads((case / "nominal.json").read_text())["mass_kg"]
        nominal = load_config(None).stand_params("final", mass)
        traces = [
            trace_of(p.name, open_recording(p).frame(), mass)
            for p in sorted(case.glob("rec_*.csv"))
        ]
    slope = dial_slope(traces)
    return [dataclasses.replace(tr, dial_slope=slope) for tr in traces], nominal


def counted(costs: Sequence[TraceCost], sizes: Sequence[int], tally: list[int]) -> list[TraceCost]:
    def one(k: int, zs: FloatArray) -> FloatArray:
        tally.append(sizes[k] * len(zs))
        return costs[k](zs)

    return [partial(one, k) for k in range(len(costs))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", type=Path, help="a folder of rec_*.csv and nominal.json")
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    traces, nominal = load(args.case)
    base = fit(Candidate.build(), traces, nominal)
    print(f"{len(traces)} traces; baseline training cost {base.train_cost:.4f}")
    print(f"{'candidate':28s} {'points':>6s} {'samples':>8s} {'plain':>8s} {'bounds':>8s} same")
    for effect in EFFECTS:
        cand = Candidate.build(effect)
        points = effect_grid_points(cand, base.values)
        costs, sizes = trace_costs(cand, traces, nominal)
        plain_s, bound_s = np.inf, np.inf
        tally: list[int] = []
        for _ in range(args.rounds):
            t0 = time.perf_counter()
            plain = int(np.argmin(sum(c(points) for c in costs)))
            t1 = time.perf_counter()
            tally.clear()
            bounded = least_cost_point(counted(costs, sizes, tally), sizes, points)
            t2 = time.perf_counter()
            plain_s, bound_s = min(plain_s, t1 - t0), min(bound_s, t2 - t1)
        share = sum(tally) / (sum(sizes) * len(points))
        print(
            f"{effect:28s} {len(points):6d} {share:8.2f} {plain_s:7.2f}s {bound_s:7.2f}s "
            f"{'yes' if plain == bounded else 'NO'}"
        )


if __name__ == "__main__":
    main()
