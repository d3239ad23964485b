"""Benchmark: what the gross-misfit test (``sim.identify.adequacy``) adds to a diagnosis.

    .venv/bin/python benchmarks/bench_own_excess.py [--rounds 3]

Per campaign (seed 1, the four moderate recordings): one whole diagnosis (its stage
times), then, side by side in turns, the remainder stage without the test and the test
alone on the diagnosis's final model. Printed: the diagnosis's total, the remainder
stage's best time without the test, the test's best time, and the test's share of the
total.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_diagnosis_trees import campaign

CAMPAIGNS = (("none", 3.096), ("none", 8.131), ("fibre_viscoelastic", 8.131))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    from sim.identify import diagnose
    from sim.identify.adequacy import own_excess
    from sim.identify.fitting import Candidate
    from sim.identify.heldout import heldout_excess
    from sim.identify.remainder import remainder_of

    print(f"{'campaign':28s} {'total s':>8s} {'remainder s':>12s} {'test s':>7s} {'share':>6s}")
    for truth, mass in CAMPAIGNS:
        traces, nominal = campaign(truth, mass)
        result = diagnose(traces, nominal)
        named = tuple(e.effect for e in result.effects)
        candidate = Candidate.build(*named)
        values = {**result.baseline}
        for e in result.effects:
            values.update({f"{e.effect}.{k}": v for k, v in e.params.items()})
        values = {p.name: values[p.name] for p in candidate.params if p.name in values}
        after = result.outputs_after
        x_base = result.remainder.excess if result.remainder else 1.0
        excess = heldout_excess(traces, after)
        without, test = [], []
        for _ in range(args.rounds):
            started = time.perf_counter()
            remainder_of(traces, after, nominal, values, x_base, balances=not named)
            without.append(time.perf_counter() - started)
            started = time.perf_counter()
            own_excess(candidate, values, traces, nominal, excess)
            test.append(time.perf_counter() - started)
        total = result.timings_s.get("total", float("nan"))
        print(f"{truth + '@' + format(mass, 'g') + ' kg':28s} {total:8.1f} {min(without):12.2f} "
              f"{min(test):7.2f} {min(test) / total:6.1%}")  # fmt: skip


if __name__ == "__main__":
    main()
