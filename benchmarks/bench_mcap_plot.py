"""Full-rate plots from MCAP files: what each way of offering them costs.

Side by side in one run, the same 2 kHz recording (bench_recordings' data: the baseline
model on a trapezoidal signal, quantised as the gauge front end delivers it) written as

* ``before``: batches (``GaugeBatch``/``CommandBatch``) and the 100 Hz ``/gauges/plot``;
* ``t_s``: the same, every batched sample also carrying its time in s (the default now:
  Foxglove's plot draws ``/gauges.u_mm[:]`` against ``/gauges.t_s[:]``);
* ``per-sample``: the batches plus one ``GaugeSample`` message per sample (2 kHz
  ``/gauges/plot``), the other way to let Foxglove plot every sample over time.

Write CPU time (best of 2), file size and the read to ``Recording.frame()``. Run::

    .venv/bin/python benchmarks/bench_mcap_plot.py [--minutes 10]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_recordings import CPU_S, make_data, write

from recordings import open_recording

VARIANTS = {
    "before": {"plot_rate_hz": 100.0, "time_s": False},
    "t_s": {"plot_rate_hz": 100.0, "time_s": True},
    "per-sample": {"plot_rate_hz": 2000.0, "time_s": False},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--block", type=int, default=100, help="samples per write call")
    args = parser.parse_args()
    g, c, d = make_data(args.minutes, quantise=True)
    duration = len(g) / 2000.0
    print(f"{len(g)} samples ({duration:.0f} s at 2 kHz), blocks of {args.block}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, options in VARIANTS.items():
            path = Path(tmp) / f"{name}.mcap"
            for _ in range(2):
                write(path, g, c, d, args.block, **options)
            cpu = CPU_S[path.name]
            t0 = time.perf_counter()
            rec = open_recording(path)
            rec.frame()
            read_s = time.perf_counter() - t0
            assert np.array_equal(rec.gauges, g) and np.array_equal(rec.command, c)
            rows.append((name, cpu, path.stat().st_size, read_s))
    base_cpu, base_size = rows[0][1], rows[0][2]
    print(f"{'variant':<12}{'write CPU s':>12}{'x real time':>13}{'MB':>8}{'size':>8}{'read s':>8}")
    for name, cpu, size, read_s in rows:
        print(
            f"{name:<12}{cpu:>12.2f}{duration / cpu:>13.0f}{size / 1e6:>8.1f}"
            f"{size / base_size:>7.2f}x{read_s:>8.2f}   (write {cpu / base_cpu:.2f}x)"
        )
    print(f"(load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
