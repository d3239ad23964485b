"""A long ``labstand run --backend sim``: lost samples and labstand's own CPU.

    .venv/bin/python benchmarks/bench_run.py [--minutes 10] [--format mcap] [--keep DIR]

Runs ``labstand run`` in this process (the simulated stand is its child process, so its
CPU is not counted), a quasi-sinusoidal 30 mm motion at 0.5 Hz for the given minutes,
then checks the recording: every 2 kHz sample there (sequence contiguous, device time
evenly spaced), drive polls at 20 Hz. CPU is ``resource.getrusage(RUSAGE_SELF)``:
all of labstand's threads (gauge reader, acquisition loop, recording writer), as a
share of one core, over the whole command and over the steady middle of the run.
Figures: docs/acquisition.md.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import resource
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from labstand.cli import main
from recordings import open_recording

FREQUENCY_HZ = 0.5


def cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def run_args(minutes: float, out: Path) -> list[str]:
    """``labstand run`` on the simulated stand: 30 mm quasi-sinusoidal at 0.5 Hz."""
    cycles = max(1, round((minutes * 60 - 2.0) * FREQUENCY_HZ))
    return [
        "run", "--backend", "sim", "--signal", "quasi-sinusoidal", "--amplitude-mm", "30",
        "--frequency-hz", str(FREQUENCY_HZ), "--cycles", str(cycles),
        "--dwell-start-s", "0.5", "--dwell-end-s", "1.5", "-o", str(out),
    ]  # fmt: skip


@dataclass(frozen=True)
class MeasuredRun:
    """What ``labstand run`` printed and the CPU it took in this process."""

    printed: str
    wall_s: float
    cpu_s: float
    steady_share: float  # of one core, from 10 s in to 5 s before the end


def measured_run(args: list[str]) -> MeasuredRun:
    """Run ``labstand ARGS`` in this process, sampling its CPU time every second."""
    samples: list[tuple[float, float]] = []
    stop = threading.Event()

    def sampler() -> None:
        while not stop.wait(1.0):
            samples.append((time.monotonic(), cpu_s()))

    watcher = threading.Thread(target=sampler, daemon=True)
    printed = io.StringIO()
    wall0, cpu0 = time.monotonic(), cpu_s()
    watcher.start()
    try:
        with contextlib.redirect_stdout(printed):
            code = main(args)
    finally:
        stop.set()
        watcher.join()
    wall, cpu = time.monotonic() - wall0, cpu_s() - cpu0
    if code != 0:
        raise SystemExit(f"labstand run exited {code}:\n{printed.getvalue()}")
    steady = [(t, c) for t, c in samples if wall0 + 10 < t < wall0 + wall - 5]
    share = (
        (steady[-1][1] - steady[0][1]) / (steady[-1][0] - steady[0][0]) if steady else cpu / wall
    )
    return MeasuredRun(printed.getvalue(), wall, cpu, share)


def bench(minutes: float, fmt: str, folder: Path) -> None:
    out = folder / f"bench-run.{fmt}"
    measured = measured_run(run_args(minutes, out))
    wall, cpu, share = measured.wall_s, measured.cpu_s, measured.steady_share
    rec = open_recording(out)
    g = rec.gauges
    seq_ok = bool(np.all(np.diff(g["seq"]) == 1))
    time_ok = bool(np.all(np.diff(g["t_ns"]) == 500_000))
    polls = len(rec.drive) / rec.duration_s
    print(f"labstand run --backend sim, {minutes:g} min quasi-sinusoidal, {fmt}: {out}")
    print(f"  {measured.printed.strip().splitlines()[-1]}")
    print(f"  samples {len(g)} ({rec.duration_s:.1f} s), lost {rec.lost_samples}, "
          f"seq contiguous {seq_ok}, device time evenly spaced {time_ok}")  # fmt: skip
    print(f"  drive polls {len(rec.drive)} ({polls:.1f} Hz), events {len(rec.events())}")
    print(f"  file {out.stat().st_size / 1e6:.1f} MB")
    print(f"  labstand CPU: {cpu:.1f} s in {wall:.1f} s = {100 * cpu / wall:.1f} % of one core "
          f"(whole command); steady run {100 * share:.1f} % of one core")  # fmt: skip
    if not (seq_ok and time_ok and rec.lost_samples == 0):
        raise SystemExit("samples were lost")


def cli() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="run length (default 10)")
    parser.add_argument("--format", choices=["mcap", "h5"], default="mcap")
    parser.add_argument("--keep", type=Path, help="write the recording here (default: a temp dir)")
    args = parser.parse_args()
    if args.keep is not None:
        args.keep.mkdir(parents=True, exist_ok=True)
        bench(args.minutes, args.format, args.keep)
        return
    with tempfile.TemporaryDirectory() as folder:
        bench(args.minutes, args.format, Path(folder))


if __name__ == "__main__":
    cli()
