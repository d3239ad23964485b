"""Reading one recording of each format in a fresh process: time, memory, what it loads.

    .venv/bin/python benchmarks/bench_formats.py [--runs 9] [--before SRC_TREE]

For every suffix of ``recordings.formats.FORMATS`` the script writes a 10 s recording
(2 kHz) with this tree's code, then reads it with ``open_recording`` in a fresh
subprocess, ``--runs`` times, the cases interleaved round-robin so the load of this
shared machine falls on all alike: median wall and CPU time (user + sys), and which
heavy libraries the read loaded. ``--before`` reads the same files also from
another source tree (e.g. ``git archive`` of the commit before the formats table) in
the same rounds. The reference is ``python -c 'import numpy'``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_startup import measure
from nptdms import ChannelObject, TdmsWriter

from recordings import COMMAND_DTYPE, GAUGES_DTYPE, make_metadata, open_recording, open_writer
from recordings.convert import write_recording
from recordings.formats import FORMATS
from sim.config import default_config

HERE = Path(__file__).resolve().parent.parent
HEAVY = ("h5py", "mcap", "nptdms", "pyarrow", "pandas", "scipy.optimize", "numba")
READ = (
    "import sys; from recordings import open_recording; open_recording(sys.argv[1]); "
    f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
)
N = 20_000


def make_files(folder: Path) -> dict[str, Path]:
    """One 10 s recording per suffix."""
    i = np.arange(N)
    g = np.zeros(N, GAUGES_DTYPE)
    g["seq"], g["t_ns"] = i, i * 500_000
    g["x_mm"], g["force_n"] = 40 * np.sin(i / 2000), 45 + np.cos(i / 100)
    g["u_mm"] = 0.9 * g["x_mm"]
    c = np.zeros(N, COMMAND_DTYPE)
    c["t_ns"], c["x_cmd_mm"] = g["t_ns"], g["x_mm"]
    source = folder / "source.mcap"
    with open_writer(source, make_metadata(default_config().to_dict(), "sim")) as w:
        w.write_gauges(g)
        w.write_command(c)
    files = {}
    for suffix, fmt in FORMATS.items():
        path = folder / f"run{suffix}"
        if suffix == ".tdms":
            wf = {"wf_increment": 0.0005}
            with TdmsWriter(path) as tdms:
                tdms.write_segment([
                    ChannelObject("Run", "x_mm", g["x_mm"], properties=wf),
                    ChannelObject("Run", "u_mm", g["u_mm"], properties=wf),
                    ChannelObject("Run", "F_N", g["force_n"], properties=wf),
                ])  # fmt: skip
        elif fmt.writer or fmt.table_writer:
            write_recording(open_recording(source), path)
        files[suffix] = path
    return files


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=9, help="runs per case (median)")
    parser.add_argument("--before", type=Path, help="another source tree to compare with")
    args = parser.parse_args()
    py = sys.executable
    trees = {"": HERE} | ({" (before)": args.before.resolve()} if args.before else {})
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        files = make_files(folder)
        cases = [("python -c 'import numpy'", [py, "-c", "import numpy"], dict(os.environ))]
        for suffix, path in files.items():
            for tag, tree in trees.items():
                env = {**os.environ, "PYTHONPATH": str(tree)}
                cases.append((f"read {suffix}{tag}", [py, "-c", READ, str(path)], env))
        loaded = {}
        for name, argv, env in cases:  # warm the file cache; note what each loads
            out = subprocess.run(
                argv, env=env, cwd=folder, capture_output=True, text=True, check=True
            )
            loaded[name] = out.stdout.split()
        walls: dict[str, list[float]] = {name: [] for name, _, _ in cases}
        cpus: dict[str, list[float]] = {name: [] for name in walls}
        load = os.getloadavg()[0]
        for _ in range(args.runs):
            for name, argv, env in cases:
                wall, cpu, _ = measure(argv, env, folder)  # (RSS: inflated by this parent's)
                walls[name].append(wall)
                cpus[name].append(cpu)
        load = (load + os.getloadavg()[0]) / 2
    print(f"median of {args.runs} runs, load average ≈ {load:.1f} ({os.cpu_count()} cores)\n")
    print("| read | wall time (median) | CPU time (median) | loads |")
    print("|---|---|---|---|")
    for name, times in walls.items():
        wall, cpu = statistics.median(times), statistics.median(cpus[name])
        libs = ", ".join(loaded[name]) or "–"
        print(f"| `{name}` | {wall:.3f} s | {cpu:.3f} s | {libs} |")


if __name__ == "__main__":
    main()
