"""A 1 s window of a 10-minute recording, and CSV/Parquet exports, side by side.

For MCAP and HDF5: ``read_window`` (reads only around the window) against the reference
``open_recording`` + cut (reads the whole file), in one run. For the table exports: write
and read back times and sizes beside MCAP's. Run::

    .venv/bin/python benchmarks/bench_window.py [--minutes 10] [--at 300]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_recordings import best, make_data, write

from labstand.cli import main as labstand_main
from recordings import open_recording
from recordings.convert import write_recording
from recordings.window import cut, read_window


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--at", type=float, default=300.0, help="window start, s")
    args = parser.parse_args()
    g, c, d = make_data(args.minutes, quantise=True)
    lo, hi = args.at, args.at + 1.0
    print(f"{len(g)} samples; window {lo:g} … {hi:g} s")
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        print(f"{'file':<10}{'window s':>10}{'whole + cut s':>15}{'ratio':>8}")
        for suffix in ("mcap", "h5"):
            path = base / f"rec.{suffix}"
            write(path, g, c, d, 100)
            win = read_window(path, lo, hi).recording
            ref = cut(open_recording(path), round(lo * 1e9), round(hi * 1e9))
            assert np.array_equal(win.gauges, ref.gauges), suffix
            t_win = best(lambda p=path: read_window(p, lo, hi))
            t_all = best(lambda p=path: cut(open_recording(p), round(lo * 1e9), round(hi * 1e9)))
            print(f"{suffix:<10}{t_win:>10.4f}{t_all:>15.3f}{t_all / t_win:>8.0f}")
        env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
        version = [sys.executable, "-m", "labstand", "--version"]
        startup = best(lambda: subprocess.run(version, env=env, check=True, capture_output=True))
        window = ["--start", str(lo), "--end", str(hi)]

        def cli(extra: list[str]) -> None:
            with open(os.devnull, "w") as sink, contextlib.redirect_stdout(sink):
                assert labstand_main(["cat", str(base / "rec.mcap"), *extra]) == 0

        print(
            f"labstand cat rec.mcap, in-process: 1 s window {best(lambda: cli(window)):.3f} s, "
            f"whole file {best(lambda: cli([]), 1):.2f} s (process start-up, "
            f"`labstand --version`: {startup:.2f} s)"
        )
        rec = open_recording(base / "rec.mcap")
        print(f"{'export':<10}{'write s':>10}{'read s':>10}{'MB':>8}")
        for suffix in ("mcap", "csv", "parquet"):
            out = base / f"out.{suffix}"
            t_w = best(lambda o=out: write_recording(rec, o), 1 if suffix == "csv" else 2)
            back = open_recording(out)
            assert np.array_equal(back.gauges, rec.gauges), suffix
            t_r = best(lambda o=out: open_recording(o), 1 if suffix == "csv" else 2)
            print(f"{suffix:<10}{t_w:>10.2f}{t_r:>10.2f}{out.stat().st_size / 1e6:>8.1f}")
    print(f"(load average {os.getloadavg()[0]:.1f}; {time.strftime('%Y-%m-%d')})")


if __name__ == "__main__":
    main()
