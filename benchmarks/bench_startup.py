"""Start-up of the labstand command: time and peak memory, side by side with numpy.

    .venv/bin/python benchmarks/bench_startup.py [--runs 11] [--before SRC_TREE]

Each command runs in a fresh subprocess, ``--runs`` times, the commands interleaved
round-robin so that the load of this shared machine falls on all of them alike; the
table gives the median wall time, the median CPU time (user + sys: what the command
costs, which the other sessions' load inflates far less than wall time) and the peak
RSS (``ru_maxrss`` of that child, from ``os.wait4``). The reference is
``python -c 'import numpy'``, the least any numerical command pays. ``--before`` runs
the same labstand commands also from another source tree (e.g. ``git archive`` of the
commit before lazy imports, unpacked), in the same rounds. ``info`` reads a small
recording the script makes first (situation 11, 4 s at 2 kHz, MCAP).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent


def measure(argv: list[str], env: dict[str, str], cwd: Path) -> tuple[float, float, float]:
    """Wall time (s), CPU time (s) and peak RSS (MB) of one run of ``argv`` (exit 0)."""
    started = time.perf_counter()
    proc = subprocess.Popen(
        argv, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - started
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        err = proc.stderr.read().decode() if proc.stderr else ""
        raise SystemExit(f"{' '.join(argv)}: exit {proc.returncode}: {err.strip()}")
    if proc.stderr:
        proc.stderr.close()
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024  # Linux: KiB


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=11, help="runs per command (median)")
    parser.add_argument("--before", type=Path, help="another source tree to compare with")
    args = parser.parse_args()

    py = sys.executable
    trees = {"": HERE} | ({" (before)": args.before.resolve()} if args.before else {})
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        rec = folder / "s11.mcap"
        env = {**os.environ, "PYTHONPATH": str(HERE)}
        subprocess.run(
            [py, "-m", "labstand", "simulate", "--situation", "11", "-o", str(rec)],
            env=env, check=True, stdout=subprocess.DEVNULL,
        )  # fmt: skip
        cases: list[tuple[str, list[str], dict[str, str]]] = [
            ("python -c 'import numpy'", [py, "-c", "import numpy"], env)
        ]
        for tag, tree in trees.items():
            tenv = {**os.environ, "PYTHONPATH": str(tree)}
            lab = [py, "-m", "labstand"]
            cases += [
                (f"labstand --help{tag}", [*lab, "--help"], tenv),
                (f"labstand simulate --help{tag}", [*lab, "simulate", "--help"], tenv),
                (f"labstand info REC{tag}", [*lab, "info", str(rec)], tenv),
                (
                    f"labstand simulate --situation 11 -o tmp.csv{tag}",
                    [*lab, "simulate", "--situation", "11", "-o", str(folder / "tmp.csv")],
                    tenv,
                ),
            ]
        for _, argv, cenv in cases:  # warm the file cache and numba's on-disk cache
            measure(argv, cenv, folder)
        walls: dict[str, list[float]] = {name: [] for name, _, _ in cases}
        cpus: dict[str, list[float]] = {name: [] for name in walls}
        rss: dict[str, float] = dict.fromkeys(walls, 0.0)
        load = os.getloadavg()[0]
        for _ in range(args.runs):
            for name, argv, cenv in cases:
                wall, cpu, peak = measure(argv, cenv, folder)
                walls[name].append(wall)
                cpus[name].append(cpu)
                rss[name] = max(rss[name], peak)
        load = (load + os.getloadavg()[0]) / 2
    print(f"median of {args.runs} runs, load average ≈ {load:.1f} ({os.cpu_count()} cores)\n")
    print("| command | wall time (median) | CPU time, user + sys (median) | peak RSS |")
    print("|---|---|---|---|")
    for name, times in walls.items():
        wall, cpu = statistics.median(times), statistics.median(cpus[name])
        print(f"| `{name}` | {wall:.3f} s | {cpu:.3f} s | {rss[name]:.0f} MB |")


if __name__ == "__main__":
    main()
