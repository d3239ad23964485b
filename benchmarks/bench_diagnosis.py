"""Benchmark: how long a diagnosis takes, what dominates, and how it scales.

A campaign of three recordings of the heavy weight (the drive motions of paper
situations 11, 10 and 12a: quick, medium, slow; ≈ 22 s in all) with a drawn real stand,
an effect and gauge noise, diagnosed blind; then the same with every recording cut to
half its cycles, to show how the time scales with recording length. The time per
candidate refit is printed from the diagnosis' own timings.

Run: ``.venv/bin/python benchmarks/bench_diagnosis.py [--effect NAME] [--seed N]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from drivers.signals import SignalSpec
from sim.checks.check import make_campaign
from sim.config import default_config
from sim.identify import diagnose
from sim.situations import situation


def campaign(scale: float) -> list[tuple[str, SignalSpec]]:
    out = []
    for name in ("11", "10", "12a"):
        spec = situation(name).signal
        cycles = max(1, round(spec.cycles * scale))
        out.append((name, SignalSpec(**{**spec.__dict__, "cycles": cycles})))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--effect", default="fibre_viscoelastic", help="the withheld truth")
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args()
    stand = default_config()
    nominal = stand.stand_params("final", 8.131)
    # Warm the numba caches so compile time is not measured.
    warm, _, _ = make_campaign(stand, "none", 8.131, np.random.default_rng(0), campaign(0.34))
    diagnose(warm[:1], nominal, candidates=["dial_gauge_calibration"])
    for scale in (1.0, 0.5):
        traces, _, _ = make_campaign(
            stand, args.effect, 8.131, np.random.default_rng(args.seed), campaign(scale)
        )
        seconds = sum(t.duration_s for t in traces)
        started = time.perf_counter()
        result = diagnose(traces, nominal)
        wall = time.perf_counter() - started
        print(
            f"campaign {seconds:5.1f} s of recordings: diagnosed in {wall:5.1f} s "
            f"({result.simulations} simulations), answer {result.effect} (truth {args.effect})"
        )
        parts = sorted(result.timings_s.items(), key=lambda kv: -kv[1])
        for name, value in parts:
            if name != "total":
                print(f"    {name:38s} {value:6.2f} s")


if __name__ == "__main__":
    main()
