"""Write and read-to-DataFrame throughput of a 10-minute 2 kHz recording, per format.

Reference: the same arrays through plain ``numpy.save`` / ``np.load``. Run::

    .venv/bin/python benchmarks/bench_recordings.py [--minutes 10] [--block 100]

The data are the baseline model driven by a trapezoidal signal, quantised as the gauge
front end delivers them (0.1 µm, 1 mN; docs/configuration.md [gauges]).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from drivers.signals import Shape, SignalSpec, plan_motion
from recordings import (
    COMMAND_DTYPE,
    DRIVE_DTYPE,
    GAUGES_DTYPE,
    make_metadata,
    open_recording,
    open_writer,
)
from sim.config import default_config
from sim.model import Model


def make_data(minutes: float, quantise: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    config = default_config()
    rate = config.sample_rate_hz
    cycles = max(int(minutes * 60 * 0.5) - 1, 1)
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.04, 0.5, cycles=cycles, dwell_end_s=1.5)
    _, x_m = plan_motion(spec, config.drive).sample(rate)
    n = int(minutes * 60 * rate)
    x_m = x_m[:n]
    res = Model(config.stand_params("final")).run(x_m, rate)
    g = np.zeros(len(x_m), GAUGES_DTYPE)
    g["seq"] = np.arange(len(x_m))
    g["t_ns"] = np.arange(len(x_m)) * int(1e9 / rate)
    g["x_mm"], g["u_mm"], g["force_n"] = res.x_m * 1e3, res.u_m * 1e3, res.force_n
    if quantise:
        g["x_mm"] = np.round(g["x_mm"] / 1e-4) * 1e-4
        g["u_mm"] = np.round(g["u_mm"] / 1e-4) * 1e-4
        g["force_n"] = np.round(g["force_n"] / 1e-3) * 1e-3
    c = np.zeros(len(x_m), COMMAND_DTYPE)
    c["t_ns"], c["x_cmd_mm"] = g["t_ns"], res.x_m * 1e3
    d = np.zeros(len(x_m) // 40, DRIVE_DTYPE)  # 50 Hz polls
    d["t_ns"] = g["t_ns"][::40][: len(d)]
    d["position_mm"] = g["x_mm"][::40][: len(d)]
    d["status_word"], d["enabled"] = 0x0041, True
    return g, c, d


def write(
    path: Path, g: np.ndarray, c: np.ndarray, d: np.ndarray, block: int, **options: float
) -> float:
    meta = make_metadata(default_config().to_dict(), "simulate")
    started, cpu = time.perf_counter(), time.process_time()
    with open_writer(path, meta, **options) as w:
        w.write_event(0, "start", "benchmark")
        j = 0
        for i in range(0, len(g), block):
            w.write_gauges(g[i : i + block])
            w.write_command(c[i : i + block])
            t_end = g["t_ns"][min(i + block, len(g)) - 1]
            k = j
            while k < len(d) and d["t_ns"][k] <= t_end:
                k += 1
            if k > j:
                w.write_drive_state(d[j:k])
                j = k
        w.write_event(int(g["t_ns"][-1]), "stop", "")
    CPU_S[path.name] = min(CPU_S.get(path.name, 1e9), time.process_time() - cpu)
    return time.perf_counter() - started


CPU_S: dict[str, float] = {}


def best(fn, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--block", type=int, default=100, help="samples per write call")
    parser.add_argument("--raw", action="store_true", help="do not quantise (full doubles)")
    parser.add_argument(
        "--plot-rate", type=float, default=100.0, help="MCAP /gauges/plot rate, Hz (0: none)"
    )
    args = parser.parse_args()
    g, c, d = make_data(args.minutes, quantise=not args.raw)
    duration = len(g) / 2000.0
    print(
        f"{len(g)} samples ({duration:.0f} s at 2 kHz), blocks of {args.block}, "
        f"MCAP plot channel {args.plot_rate:g} Hz"
    )
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        rows = []
        npy = base / "g.npy"
        t_w = best(
            lambda: (np.save(npy, g), np.save(base / "c.npy", c), np.save(base / "d.npy", d))
        )
        t_r = best(lambda: (np.load(npy), np.load(base / "c.npy"), np.load(base / "d.npy")))
        size = sum(p.stat().st_size for p in base.glob("*.npy"))

        def numpy_frame() -> pd.DataFrame:
            a, b = np.load(npy), np.load(base / "c.npy")
            return pd.DataFrame(
                {
                    "x_cmd_mm": b["x_cmd_mm"],
                    "x_mm": a["x_mm"],
                    "u_mm": a["u_mm"],
                    "F_N": a["force_n"],
                    "seq": a["seq"],
                    "flags": a["flags"],
                },
                index=pd.Index(a["t_ns"] / 1e9, name="t_s"),
            )

        t_rf = best(numpy_frame)
        rows.append(("numpy .npy", t_w, t_r, t_rf, size))
        for suffix in ("mcap", "h5", "plain.h5"):
            path = base / f"rec.{suffix}"
            options: dict[str, float] = {"plot_rate_hz": args.plot_rate} if suffix == "mcap" else {}
            if suffix == "plain.h5":
                options["compress"] = False
            t_w = min(write(path, g, c, d, args.block, **options) for _ in range(2))
            rec = open_recording(path)
            assert np.array_equal(rec.gauges, g) and np.array_equal(rec.command, c)
            t_rf = best(lambda p=path: open_recording(p).frame())
            rows.append((suffix.upper(), t_w, float("nan"), t_rf, path.stat().st_size))
    load_ref, frame_ref = rows[0][2], rows[0][3]
    print(
        f"{'format':<22}{'write s':>9}{'x real time':>13}{'read->DataFrame s':>19}"
        f"{'x np.load':>11}{'x np.load+DataFrame':>21}{'MB':>7}"
    )
    for name, t_w, _, t_rf, size in rows:
        cpu = CPU_S.get(f"rec.{name.lower()}")
        label = name if cpu is None else f"{name} (cpu {cpu:.1f} s)"
        print(
            f"{label:<22}{t_w:>9.3f}{duration / t_w:>13.0f}{t_rf:>19.3f}"
            f"{t_rf / load_ref:>11.1f}{t_rf / frame_ref:>21.1f}{size / 1e6:>7.1f}"
        )
    print(f"(np.load alone: {load_ref:.3f} s; load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
