"""Benchmark: what laying a named effect's grid again (``refitting.grid_again``) adds to its polish.

    .venv/bin/python benchmarks/bench_grid_again.py [--rounds 3]

Per campaign (same-form check campaigns, heavy weight, the moderate recordings): the
polish of the true effect's candidate from the truth's values, with the grid again and
without it, in turns; printed: the median of each and the grid's share.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: (effect, check seed): the campaigns whose coverage misses led to the grid again.
CAMPAIGNS = (("pulley_inertia_friction", 8), ("fibre_transverse_vibration", 8),
             ("fibre_pulley_jump", 6))  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    import numpy as np

    import sim.identify.refitting as refitting
    from sim.checks.check import check_cases, make_campaign, recording_set
    from sim.config import load_config
    from sim.identify.candidates import Candidate, FitResult
    from sim.identify.fitting import Objective
    from sim.identify.screening import outputs_of

    stand = load_config(None)
    with_grid = refitting.grid_again

    def without_grid(res: FitResult, *_: object) -> tuple[FitResult, int]:
        return res, 0

    print(f"{'campaign':36s} {'with s':>7s} {'without s':>10s} {'grid share':>11s}")
    for effect, seed in CAMPAIGNS:
        (spec,) = [s for s in check_cases(seed, 1, [effect]) if s.mass_kg > 5.0]
        campaign = recording_set("moderate", stand)
        traces, _, truth = make_campaign(stand, effect, spec.mass_kg, spec.rng(), campaign)
        nominal = stand.stand_params("final", spec.mass_kg)
        candidate = Candidate.build(effect)
        start = {p.name: truth.get(p.name.split(".")[-1], 0.5 * (p.low + p.high))
                 for p in candidate.params}  # fmt: skip
        start = candidate.natural(candidate.internal(start))
        residuals = Objective(candidate, traces, nominal).residuals(candidate.internal(start))
        outputs = outputs_of(candidate, start, traces, nominal)
        fitted = refitting.Fitted(
            FitResult(candidate, start, float(np.sum(residuals**2)), 0), outputs, np.inf
        )
        times: dict[str, list[float]] = {"with": [], "without": []}
        refitting.polish(fitted, traces, nominal)  # compiled and warm
        for _ in range(args.rounds):
            for name, grid in (("with", with_grid), ("without", without_grid)):
                refitting.grid_again = grid  # type: ignore[assignment]
                began = time.perf_counter()
                refitting.polish(fitted, traces, nominal)
                times[name].append(time.perf_counter() - began)
        refitting.grid_again = with_grid
        w, wo = statistics.median(times["with"]), statistics.median(times["without"])
        print(f"{effect + f' (seed {seed})':36s} {w:7.2f} {wo:10.2f} {(w - wo) / w:11.0%}")


if __name__ == "__main__":
    main()
