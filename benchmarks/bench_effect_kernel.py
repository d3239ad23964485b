"""Benchmark: the model with effects (the union of the built-in terms) now and in another tree.

    .venv/bin/python benchmarks/bench_effect_kernel.py [--before SRC_TREE] [--rounds 2]

The baseline kernel (``make bench``) does not run when an effect is on; the effects'
kernel does, and the diagnosis' candidate refits spend most of their time in it. Each
round runs this script's measurement in a fresh process from this tree and, with
``--before``, from the other tree (e.g. ``git worktree add --detach /tmp/before COMMIT``),
in turns, so that the load of this shared machine falls on both alike; the table gives
the best of the rounds, wall time and the process's CPU time (user + sys, all threads:
a batch runs on both cores, and when other sessions hold one its wall time doubles, its
CPU time much less). Measured: situation 11's motion for 60 s at 2 kHz, 8.131 kg,
``Model(stand, [effect]).run`` (best of 5) and ``run_batch`` of 32 parameter sets (best
of 2), for one cheap and one costly physical effect and all six physical ones together.
The stiff cases (a light pulley at four times the damping, LuGre at
σ₀ = 1e6 N/m) show the exponential step of the rim and the bristle (docs/effects.md).
Compile time is excluded (each process compiles nothing once numba's cache is warm:
run the script once before timing a fresh tree).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
RATE = 2000.0
# Spelled out, not read from a registry: both trees (old and new) must run the same list.
# Per case: the effects with their parameters, and a factor on the stand's damping.
Case = tuple[list[tuple[str, dict[str, float]]], float]
CASES: dict[str, Case] = {
    "side_load_friction": ([("side_load_friction", {})], 1.0),
    "pulley_inertia_friction": ([("pulley_inertia_friction", {})], 1.0),
    # The stiff decays (ETDRK4 where it pays, docs/effects.md): a light, damped pulley's
    # rim and a stiff LuGre bristle.
    "light pulley, 4x damping": ([("pulley_inertia_friction", {"inertia_kg_m2": 1e-5})], 4.0),
    "stick_slip_friction": ([("stick_slip_friction", {})], 1.0),
    "LuGre at 1e6 N/m": ([("stick_slip_friction", {"bristle_stiffness_n_m": 1e6})], 1.0),
    "all six physical": (
        [
            (name, {})
            for name in (
                "fibre_viscoelastic",
                "fibre_transverse_vibration",
                "fibre_pulley_jump",
                "pulley_inertia_friction",
                "stick_slip_friction",
                "side_load_friction",
            )
        ],
        1.0,
    ),
}


def best_of(fn: Callable[[], object], repeats: int) -> list[float]:
    """[best wall time, best CPU time of the process] (s) of ``repeats`` calls."""
    walls, cpus = [], []
    for _ in range(repeats):
        start, cpu = time.perf_counter(), time.process_time()
        fn()
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - cpu)
    return [min(walls), min(cpus)]


def measure(seconds: float, batch: int) -> dict[str, list[float]]:
    """{case: [run, run CPU, batch, batch CPU] (s)} in this process (its tree on sys.path)."""
    import dataclasses

    import numpy as np

    from drivers.signals import SignalSpec, plan_motion
    from sim.config import default_config
    from sim.effects import EffectSpec
    from sim.model import Model
    from sim.situations import situation

    stand = default_config()
    s11 = situation("11")
    cycles = max(1, round((seconds - 1.5) * s11.signal.frequency_hz))
    spec = SignalSpec(**{**s11.signal.__dict__, "cycles": cycles})
    _, x = plan_motion(spec, stand.drive).sample(RATE)
    nominal = stand.stand_params("final", s11.mass_kg)
    out = {}
    for case, (effects, damping) in CASES.items():
        params = dataclasses.replace(nominal, damping_n_s_m=nominal.damping_n_s_m * damping)
        rng = np.random.default_rng(1)
        variants = [
            {
                "stiffness_n_m": params.stiffness_n_m * rng.uniform(0.75, 1.25),
                "damping_n_s_m": params.damping_n_s_m * rng.uniform(0.75, 1.25),
                "friction_scale": rng.uniform(0.75, 1.25),
            }
            for _ in range(batch)
        ]
        model = Model(params, [EffectSpec(name, values) for name, values in effects])
        model.run(x[:100], RATE)  # load (or compile) the kernel
        model.run_batch(x[:100], RATE, variants[:2])
        single = best_of(partial(model.run, x, RATE), 5)
        many = best_of(partial(model.run_batch, x, RATE, variants), 2)
        out[case] = single + many
    return out


def child(tree: Path, seconds: float, batch: int) -> dict[str, list[float]]:
    """``measure`` in a fresh process with ``tree`` first on its path."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    argv = [sys.executable, __file__, "--child", str(seconds), str(batch)]
    done = subprocess.run(argv, env=env, cwd=tree, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"measuring {tree} failed:\n{done.stderr}")
    result: dict[str, list[float]] = json.loads(done.stdout.splitlines()[-1])
    return result


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        print(json.dumps(measure(float(sys.argv[2]), int(sys.argv[3]))))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, help="another source tree to measure alike")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--seconds", type=float, default=60.0, help="simulated duration, s")
    parser.add_argument("--batch", type=int, default=32, help="parameter sets in the batch")
    args = parser.parse_args()
    trees = {"now": HERE} | ({"before": args.before.resolve()} if args.before else {})
    best: dict[str, dict[str, list[float]]] = {}
    loads = []
    for _ in range(args.rounds):
        for label, tree in reversed(trees.items()):  # before, now, before, now, ...
            loads.append(os.getloadavg()[0])
            for case, times in child(tree, args.seconds, args.batch).items():
                old = best.setdefault(label, {}).setdefault(case, times)
                best[label][case] = [min(a, b) for a, b in zip(old, times, strict=True)]
    print(
        f"load average {min(loads):.1f}-{max(loads):.1f} (1 min, at each process start); "
        f"best of {args.rounds} rounds per tree; CPU: user + sys of all threads"
    )
    head = ["one run", "CPU", f"batch of {args.batch}", "CPU"]
    print(f"{'case':26s} {'tree':10s}" + "".join(f"{h:>14s}" for h in head))
    for case in CASES:
        for label in trees:
            cells = [f"{v * 1e3:11.1f} ms" for v in best[label][case][:2]]
            cells += [f"{v:12.2f} s" for v in best[label][case][2:]]
            print(f"{case:26s} {label:10s}" + "".join(cells))
        if "before" in best:
            now, before = best["now"][case], best["before"][case]
            ratios = "".join(f"{a / b:14.3f}" for a, b in zip(now, before, strict=True))
            print(f"{'':26s} {'now/before':10s}" + ratios)


if __name__ == "__main__":
    main()
