"""Benchmark: the model's one pathway (issue 32) against another source tree, side by side.

    git archive b677bbe | tar -x -C /tmp/before     # main before the refactor
    .venv/bin/python benchmarks/bench_physics.py --before /tmp/before [--rounds 2]

Each round measures, in a fresh process per tree and in turns (before, now, before, now),
so that this shared machine's load falls on both alike: situation 11's motion for 60 s
at 2 kHz, 8.131 kg, ``Model(stand, effects).run`` (best of 5) and ``run_batch`` (best of
2) — the baseline with 256 parameter sets, each physical effect alone and all six
together with 32 — wall time and the process's CPU time (user + sys, all threads). The
table gives the best of the rounds. Compile time is excluded there (each process loads
numba's cache, warmed first); ``--cold`` also times, once per tree, a fresh process on an
empty cache (NUMBA_CACHE_DIR and LABSTAND_KERNEL_CACHE in a new temporary folder) until
the baseline and one physical effect have each run from rest, as a batch and as segments.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
RATE = 2000.0
# Spelled out, not read from a registry: both trees (old and new) must run the same list.
PHYSICAL = (
    "fibre_viscoelastic",
    "fibre_transverse_vibration",
    "fibre_pulley_jump",
    "pulley_inertia_friction",
    "stick_slip_friction",
    "side_load_friction",
)
CASES: dict[str, tuple[list[str], int]] = {
    "baseline": ([], 256),
    **{name: ([name], 32) for name in PHYSICAL},
    "all six physical": (list(PHYSICAL), 32),
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


def measure(seconds: float, cases: list[str]) -> dict[str, list[float]]:
    """{case: [run, run CPU, batch, batch CPU] (s)} in this process (its tree on sys.path)."""
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
    params = stand.stand_params("final", s11.mass_kg)
    out = {}
    for case in cases:
        effects, batch = CASES[case]
        rng = np.random.default_rng(1)
        variants = [
            {
                "stiffness_n_m": params.stiffness_n_m * rng.uniform(0.75, 1.25),
                "damping_n_s_m": params.damping_n_s_m * rng.uniform(0.75, 1.25),
                "friction_scale": rng.uniform(0.75, 1.25),
            }
            for _ in range(batch)
        ]
        model = Model(params, [EffectSpec(name) for name in effects])
        model.run(x[:100], RATE)  # load (or compile) the kernel
        model.run_batch(x[:100], RATE, variants[:2])
        single = best_of(partial(model.run, x, RATE), 5)
        many = best_of(partial(model.run_batch, x, RATE, variants), 2)
        out[case] = single + many
    return out


def cold() -> dict[str, list[float]]:
    """{"cold": [wall, CPU]} (s) until the baseline and one effect ran every way, compiling."""
    start, cpu = time.perf_counter(), time.process_time()
    import numpy as np

    from sim.config import default_config
    from sim.effects import EffectSpec
    from sim.model import Model, Restarts

    p = default_config().stand_params("final", 8.131)
    t = np.arange(400) / RATE
    x = -0.002 * np.sin(2 * np.pi * 5 * t) ** 2
    for effects in ([], [EffectSpec("side_load_friction")]):
        model = Model(p, effects)
        run = model.run(x, RATE)
        model.run_batch(x, RATE, [{}, {"friction_scale": 1.1}])
        starts, lengths = np.array([0, 200]), np.array([200, 200])
        model.run_segments(x, RATE, Restarts(starts, lengths, run.u_m, run.v_m_s, run.force_n))
    return {"cold": [time.perf_counter() - start, time.process_time() - cpu]}


def child(
    tree: Path, mode: str, seconds: float, cache: str | None = None, cases: str = ""
) -> dict[str, list[float]]:
    """``measure`` (or ``cold``) in a fresh process with ``tree`` first on its path."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    if cache is not None:
        env |= {"NUMBA_CACHE_DIR": cache, "LABSTAND_KERNEL_CACHE": str(Path(cache) / "kernels")}
    argv = [sys.executable, __file__, f"--{mode}-child", str(seconds), cases or ",".join(CASES)]
    done = subprocess.run(argv, env=env, cwd=tree, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"measuring {tree} failed:\n{done.stderr}")
    result: dict[str, list[float]] = json.loads(done.stdout.splitlines()[-1])
    return result


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] in ("--measure-child", "--cold-child"):
        seconds, cases = float(sys.argv[2]), sys.argv[3].split(",")
        print(json.dumps(measure(seconds, cases) if "measure" in sys.argv[1] else cold()))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, help="another source tree to measure alike")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--seconds", type=float, default=60.0, help="simulated duration, s")
    parser.add_argument("--cold", action="store_true", help="also time a compile from empty")
    parser.add_argument("--cases", default="", help="comma-separated cases (default: all)")
    args = parser.parse_args()
    cases = [c for c in args.cases.split(",") if c] or list(CASES)
    trees = {"now": HERE} | ({"before": args.before.resolve()} if args.before else {})
    if args.cold:
        for label, tree in reversed(trees.items()):
            with tempfile.TemporaryDirectory() as cache:
                load = os.getloadavg()[0]
                wall, cpu = child(tree, "cold", args.seconds, cache)["cold"]
                print(
                    f"cold compile, {label}: {wall:.1f} s wall, {cpu:.1f} s CPU (load {load:.1f})"
                )
    for tree in trees.values():
        child(tree, "measure", 2.0, cases=",".join(cases))  # warm numba's cache in each tree
    best: dict[str, dict[str, list[float]]] = {}
    loads = []
    for _ in range(args.rounds):
        for label, tree in reversed(trees.items()):  # before, now, before, now, ...
            loads.append(os.getloadavg()[0])
            for case, times in child(tree, "measure", args.seconds, cases=",".join(cases)).items():
                old = best.setdefault(label, {}).setdefault(case, times)
                best[label][case] = [min(a, b) for a, b in zip(old, times, strict=True)]
    print(f"load average during the rounds: {min(loads):.1f}–{max(loads):.1f} (2 cores)")
    print(
        "| case | run (ms) | run CPU (ms) | batch (s) | batch CPU (s) |"
        + (" run vs before | batch vs before |" if "before" in best else "")
    )
    print("|---|---|---|---|---|" + ("---|---|" if "before" in best else ""))
    for case in cases:
        size = CASES[case][1]
        for label in trees:
            run, run_cpu, batch, batch_cpu = best[label][case]
            row = f"| {case}, {label} (batch {size}) | {run * 1e3:.1f} | {run_cpu * 1e3:.1f} | "
            row += f"{batch:.2f} | {batch_cpu:.2f} |"
            if "before" in best:
                ref = best["before"][case]
                row += f" {run / ref[0]:.3f} | {batch / ref[2]:.3f} |" if label == "now" else " | |"
            print(row)


if __name__ == "__main__":
    main()
