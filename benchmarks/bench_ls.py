"""``labstand ls`` over a folder of many recordings: it reads only metadata and spans.

Writes N recordings of S seconds each (2 kHz gauges, command and 50 Hz drive polls, as a
run records them; 80 % MCAP, 10 % HDF5, 5 % CSV, 5 % Parquet; operators, samples and
tags varied), then times the command as a user runs it (a fresh process, start-up
included), best and median of R runs::

    .venv/bin/python benchmarks/bench_ls.py [--n 1000] [--seconds 10] [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from recordings import COMMAND_DTYPE, DRIVE_DTYPE, GAUGES_DTYPE, make_metadata, open_recording
from recordings.convert import write_recording
from recordings.schema import RecordingMetadata
from sim.config import default_config

OPERATORS = ("ana", "bo", "chen", "dara")


def arrays(seconds: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A quantised run-like recording: gauges, command, drive polls."""
    n = int(seconds * 2000)
    t_ns = np.arange(n, dtype=np.int64) * 500_000
    x = 12.5 * (1 - np.cos(2 * np.pi * 2.0 * t_ns / 1e9))
    g = np.zeros(n, GAUGES_DTYPE)
    g["seq"], g["t_ns"] = np.arange(n), t_ns
    g["x_mm"] = np.round(x / 1e-4) * 1e-4
    g["u_mm"] = np.round(0.9 * x / 1e-4) * 1e-4
    g["force_n"] = np.round((45 + 2 * x) / 1e-3) * 1e-3
    c = np.zeros(n, COMMAND_DTYPE)
    c["t_ns"], c["x_cmd_mm"] = t_ns, x
    d = np.zeros(n // 40, DRIVE_DTYPE)
    d["t_ns"], d["position_mm"], d["enabled"] = t_ns[::40][: len(d)], x[::40][: len(d)], True
    return g, c, d


def metadata(i: int) -> RecordingMetadata:
    return make_metadata(
        default_config().to_dict(),
        "sim",
        signal={"shape": "trapezoidal", "amplitude_mm": 25.0, "frequency_hz": 2.0, "cycles": 5},
        operator=OPERATORS[i % len(OPERATORS)],
        sample=f"F-{i % 37:02d}",
        tags=("warm",) if i % 3 == 0 else (),
        operator_note=f"benchmark recording {i}",
    )


def make_folder(folder: Path, n: int, seconds: float) -> None:
    from recordings import open_writer

    g, c, d = arrays(seconds)
    template = folder / "template.mcap"
    with open_writer(template, metadata(0)) as w:
        w.write_gauges(g)
        w.write_command(c)
        w.write_drive_state(d)
    base = open_recording(template)
    template.unlink()
    for i in range(n):
        suffix = ".mcap" if i % 20 < 16 else ".h5" if i % 20 < 18 else (".csv", ".parquet")[i % 2]
        path = folder / f"run-{i:04d}{suffix}"
        if suffix in {".mcap", ".h5"}:
            with open_writer(path, metadata(i)) as w:
                w.write_event(0, "start", "benchmark")
                for lo in range(0, len(g), 2000):  # one second a block, as a run writes
                    w.write_gauges(g[lo : lo + 2000])
                    w.write_command(c[lo : lo + 2000])
                w.write_drive_state(d)
                w.write_event(int(g["t_ns"][-1]), "stop", "profile done")
        else:
            write_recording(base, path, metadata(i))


def timed(argv: list[str], repeat: int) -> tuple[float, float, str]:
    times, out = [], ""
    for _ in range(repeat):
        started = time.perf_counter()
        done = subprocess.run(argv, capture_output=True, text=True, check=True)
        times.append(time.perf_counter() - started)
        out = done.stdout
    return min(times), statistics.median(times), out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        started = time.perf_counter()
        make_folder(folder, args.n, args.seconds)
        size = sum(p.stat().st_size for p in folder.iterdir()) / 1e6
        print(
            f"{args.n} recordings of {args.seconds:g} s ({size:.0f} MB) written in "
            f"{time.perf_counter() - started:.1f} s"
        )
        exe = [sys.executable, "-m", "labstand", "ls"]
        for label, extra in (
            ("ls DIR", []),
            ("ls DIR --json", ["--json"]),
            ("ls DIR --operator bo --tag warm", ["--operator", "bo", "--tag", "warm"]),
        ):
            best, median, out = timed([*exe, str(folder), *extra], args.repeat)
            rows = out.count("\n") - 1 if not extra or extra[0] != "--json" else out.count('"path"')
            print(f"  labstand {label:32s} best {best:.2f} s, median {median:.2f} s ({rows} rows)")


if __name__ == "__main__":
    main()
