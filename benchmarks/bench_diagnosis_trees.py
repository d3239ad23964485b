"""Benchmark: a 4-recording diagnosis in two source trees, side by side (issue 32).

    git archive b677bbe | tar -x -C /tmp/before     # main before the refactor
    .venv/bin/python benchmarks/bench_diagnosis_trees.py --before /tmp/before [--rounds 2]

Each campaign (a same-form truth at a weight, seed 1, the four moderate recordings) is
diagnosed in a fresh process per tree, in turns (before, now, before, now), so that this
machine's load falls on both alike. In each process the campaign is diagnosed twice and
the second is timed (the first loads numba's caches). This tree's "how sure" stage
(intervals and per-recording fits, added after the refactor) is left out so that both
trees do the same work. Printed: per campaign, the best wall and process CPU time (user
+ sys, all threads) of the rounds, and whether both trees named the same effects.

``--objective``: what a diagnosis spends its time on, alone: the training objective of
each campaign's candidate (its own effect; the baseline for ``none``) evaluated for a
batch of 8 parameter sets, best CPU time of 7, one numba thread, in each tree.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent.parent
CAMPAIGNS = (("none", 3.096), ("fibre_viscoelastic", 8.131), ("stick_slip_friction", 3.096))
EMPTY_SURE = {"baseline_intervals": {}, "baseline_reaches_bound": [], "gap_closure_interval": None,
              "gap_intervals": {}, "interval_method": "", "per_recording": {}, "consistency": {},
              "baseline_consistency": {}}  # fmt: skip


def campaign(truth: str, mass: float) -> tuple[list[Any], Any]:
    """The campaign's traces (seed 1, moderate recordings) and nominal, in this tree."""
    import importlib

    try:
        check = importlib.import_module("sim.checks.check")
    except ImportError:  # the tree before the refactor
        check = importlib.import_module("sim.identify.check")
    from sim.config import load_config

    stand = load_config(None)
    spec = check.CaseSpec(truth, mass, 0, 1)
    traces, _, _ = check.make_campaign(stand, truth, mass, spec.rng(),
                                       check.recording_set("moderate", stand))  # fmt: skip
    return traces, stand.stand_params("final", mass)


def measure(truth: str, mass: float) -> dict[str, object]:
    """Diagnose the campaign twice in this process (its tree on sys.path); time the second."""
    import importlib

    from sim.identify import diagnose

    try:
        pipeline = importlib.import_module("sim.identify.pipeline")
        pipeline.how_sure = lambda *_a, **_k: dict(EMPTY_SURE)  # type: ignore[attr-defined]
    except ImportError:  # the tree before the refactor
        pass
    traces, nominal = campaign(truth, mass)
    diagnose(traces, nominal)
    wall, cpu = time.perf_counter(), time.process_time()
    d = diagnose(traces, nominal)
    return {"wall": time.perf_counter() - wall, "cpu": time.process_time() - cpu,
            "named": sorted(a.effect for a in d.effects)}  # fmt: skip


def objective(truth: str, mass: float) -> dict[str, object]:
    """Best CPU time of the candidate's objective over a batch of 8 sets (this tree)."""
    import dataclasses

    import numpy as np

    from sim.identify.fitting import Candidate, Objective
    from sim.identify.shooting import dial_slope

    traces, nominal = campaign(truth, mass)
    slope = dial_slope(traces)
    traces = [dataclasses.replace(tr, dial_slope=slope) for tr in traces]
    cand = Candidate.build() if truth == "none" else Candidate.build(truth)
    obj = Objective(cand, traces, nominal, 4)
    middle = {p.name: 0.5 * (p.low + p.high) for p in cand.params}
    z = cand.internal({**middle, "stiffness_scale": 1.0, "damping_scale": 1.0})
    zs = np.stack([z] * 8)
    obj.residuals_batch(zs)
    times = []
    for _ in range(7):
        cpu = time.process_time()
        obj.residuals_batch(zs)
        times.append(time.process_time() - cpu)
    return {"wall": min(times), "cpu": min(times), "named": []}


def child(tree: Path, truth: str, mass: float, mode: str = "--child") -> dict[str, object]:
    env = {**os.environ, "PYTHONPATH": str(tree), "NUMBA_NUM_THREADS": "1"}
    if mode == "--child":
        env.pop("NUMBA_NUM_THREADS")
    argv = [sys.executable, __file__, mode, truth, str(mass)]
    done = subprocess.run(argv, env=env, cwd=tree, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{tree}: {done.stderr.strip().splitlines()[-1]}")
    return json.loads(done.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] in ("--child", "--objective-child"):
        work = measure if sys.argv[1] == "--child" else objective
        print(json.dumps(work(sys.argv[2], float(sys.argv[3]))))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, required=True, help="the other source tree")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--objective", action="store_true", help="time the objective alone")
    parser.add_argument("--only", help="one campaign, TRUTH@KG (default: the three)")
    args = parser.parse_args()
    chosen = CAMPAIGNS
    if args.only:
        truth, kg = args.only.split("@")
        chosen = ((truth, float(kg)),)
    mode = "--objective-child" if args.objective else "--child"

    def fmt(seconds: object) -> str:
        value = float(seconds)  # type: ignore[arg-type]
        return f"{value * 1e3:.1f} ms" if args.objective else f"{value:.1f} s"

    trees = {"before": args.before.resolve(), "now": HERE}
    best: dict[tuple[str, str], dict[str, object]] = {}
    for r in range(args.rounds):
        for truth, mass in chosen:
            for label, tree in trees.items():
                got = child(tree, truth, mass, mode)
                key = (f"{truth} {mass:g} kg", label)
                old = best.get(key)
                best[key] = (
                    got
                    if old is None
                    else {
                        **got,
                        "wall": min(got["wall"], old["wall"]),  # type: ignore[type-var]
                        "cpu": min(got["cpu"], old["cpu"]),  # type: ignore[type-var]
                    }
                )
                print(f"round {r + 1} {key[0]} {label}: {fmt(got['wall'])} wall, "
                      f"{fmt(got['cpu'])} CPU, named {got['named']}", flush=True)  # fmt: skip
    print("| campaign | wall, before | wall, now | CPU, before | CPU, now | same answer |")
    print("|---|---|---|---|---|---|")
    for truth, mass in chosen:
        name = f"{truth} {mass:g} kg"
        b, n = best[(name, "before")], best[(name, "now")]
        print(
            f"| {name} | {fmt(b['wall'])} | {fmt(n['wall'])} | {fmt(b['cpu'])} | "
            f"{fmt(n['cpu'])} | {'yes' if b['named'] == n['named'] else 'NO'} |"
        )


if __name__ == "__main__":
    main()
