"""Benchmark: independent fits side by side in serial lanes, against one after the other.

    .venv/bin/python benchmarks/bench_lanes.py [--rounds 2] [--seed 1]

A diagnosis runs many independent fits: the baseline's three starts, the nine
candidates' refits, the further effects' refits, the bootstrap replicates, the
per-recording fits. With lanes (``sim.identify.side_by_side.in_lanes``) they run two at
a time, each on its own thread with the kernels' serial variants; the reference runs
them one after the other, each batch on all cores (as before lanes). Three campaigns of
the other stand (four recordings each, ~22 s: quick, rectangle, burst, slow; a light
dial gauge's gain, a heavy Maxwell branch, light stick-slip), each diagnosed both ways
in the same rounds, alternating which goes first. The answers must be identical (the
serial kernels compute every item as the parallel ones); the table gives the median
wall time per step.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import numba
import numpy as np

from labstand.diagnosis_report import report_json
from sim.checks.check import make_campaign
from sim.config import default_config
from sim.identify import diagnose, fitting, intervals, naming, per_recording, pipeline
from sim.identify.side_by_side import in_lanes

T = TypeVar("T")
CAMPAIGNS = (
    ("dial_gauge_calibration", 3.096),
    ("fibre_viscoelastic", 8.131),
    ("stick_slip_friction", 3.096),
)
STEPS = ("baseline_fit", "refits", "further_effects", "intervals", "total")
USERS = (fitting, intervals, naming, per_recording, pipeline)


def in_turn(work: Callable[[int], T], sizes: Sequence[float]) -> list[T]:
    """The reference: the items one after the other, each batch on all cores."""
    return [work(k) for k in range(len(sizes))]


def use(lanes: Callable[..., Any]) -> None:
    for module in USERS:
        module.in_lanes = lanes  # type: ignore[attr-defined]


def answer(result: Any) -> str:
    out = report_json(result, None)
    for key in ("timings_s", "provenance"):
        out.pop(key, None)
    return json.dumps(out, sort_keys=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    stand = default_config()
    campaigns = []
    for effect, mass in CAMPAIGNS:
        traces, _, _ = make_campaign(
            stand, effect, mass, np.random.default_rng(args.seed), truth_stand="other"
        )
        campaigns.append((effect, mass, traces))
    # Warm the kernels, so that compile time is not measured.
    warm = ["dial_gauge_calibration"]
    diagnose(campaigns[0][2][:1], stand.stand_params("final", 3.096), candidates=warm)
    print(f"numba threads: {numba.get_num_threads()}, rounds: {args.rounds}")
    times: dict[tuple[str, str], list[dict[str, float]]] = {}
    for r in range(args.rounds):
        for effect, mass, traces in campaigns:
            answers = {}
            for mode in ("lanes", "in turn") if r % 2 == 0 else ("in turn", "lanes"):
                use(in_lanes if mode == "lanes" else in_turn)
                started = time.perf_counter()
                result = diagnose(traces, stand.stand_params("final", mass))
                wall = time.perf_counter() - started
                answers[mode] = answer(result)
                steps = {k: result.timings_s.get(k, 0.0) for k in STEPS[:-1]}
                times.setdefault((effect, mode), []).append({**steps, "total": wall})
                print(f"round {r} {effect:24s} {mode:8s} {wall:6.1f} s, answer {result.effect}",
                      flush=True)  # fmt: skip
            same = answers["lanes"] == answers["in turn"]
            print(f"        identical answers: {same}", flush=True)
            if not same:
                raise SystemExit(f"{effect}: lanes changed the answer")
    use(in_lanes)
    print(f"\n| campaign | mode | {' | '.join(STEPS)} |")
    print(f"|---|---|{'---|' * len(STEPS)}")
    for (effect, mode), rows in times.items():
        cells = " | ".join(f"{statistics.median(r[s] for r in rows):.1f}" for s in STEPS)
        print(f"| {effect} | {mode} | {cells} |")


if __name__ == "__main__":
    main()
