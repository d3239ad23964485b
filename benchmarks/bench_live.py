"""The live view's cost: CPU of a whole ``labstand run`` at 2 kHz with one client vs none.

    .venv/bin/python benchmarks/bench_live.py [--minutes 2]

Side by side in one invocation, the same ``labstand run --backend sim`` (quasi-sinusoidal
30 mm at 0.5 Hz, as bench_run.py) twice in this process: without a viewer, then with
``--foxglove`` and one independent client reading every topic (``@foxglove/ws-protocol``
in Node, tests/live/node/client.js; ``make node-tools`` installs it). CPU is
``getrusage(RUSAGE_SELF)``: every labstand thread, the SDK's server threads included, as
a share of one core over the steady middle of the run (the simulated stand and the
client are other processes). The added latency is the client's arrival wall time minus
the sample's log time (the wall time its first block reached labstand, then the gauge
clock: on the simulated stand that clock is the host's, so nothing drifts).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import socket
import subprocess
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from bench_run import measured_run, run_args  # the same run, measured the same way

from recordings import open_recording

CLIENT = Path(__file__).parent.parent / "tests" / "live" / "node" / "client.js"


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def run(minutes: float, out: Path, port: int | None) -> tuple[float, float, str]:
    """One run; (steady CPU share, whole-command share, the live-view line)."""
    args = run_args(minutes, out)
    if port is not None:
        args += ["--foxglove", str(port)]
    measured = measured_run(args)
    live = next((ln for ln in measured.printed.splitlines() if "samples published" in ln), "")
    return measured.steady_share, measured.cpu_s / measured.wall_s, live.strip()


def bench(minutes: float, folder: Path) -> None:
    plain = folder / "plain.mcap"
    share0, whole0, _ = run(minutes, plain, None)
    port = free_port()
    client = subprocess.Popen(
        ["node", str(CLIENT), f"ws://127.0.0.1:{port}", "--latency"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    viewed = folder / "viewed.mcap"
    try:
        share1, whole1, live = run(minutes, viewed, port)
        out, _ = client.communicate(timeout=120)
    finally:
        if client.poll() is None:
            client.kill()
            client.communicate()
    node_cpu = os.times().children_user + os.times().children_system  # rough: all children
    report: dict[str, Any] = json.loads(out.splitlines()[-1])
    gauges = report["topics"]["/gauges"]
    rec = open_recording(viewed)
    log_ns = np.array([int(t) for t in gauges["logTimes"]], dtype=np.int64)
    recv_ns = np.array(gauges["recvNs"], dtype=np.int64)
    latency_ms = (recv_ns - log_ns) / 1e6
    p50, p99, worst = np.percentile(latency_ms, [50, 99, 100])
    every = gauges["seq"] == rec.gauges["seq"].tolist()
    print(f"labstand run --backend sim, {minutes:g} min quasi-sinusoidal 30 mm at 0.5 Hz, 2 kHz")
    print(f"  without a viewer: {100 * share0:.1f} % of one core steady "
          f"({100 * whole0:.1f} % over the whole command)")  # fmt: skip
    print(f"  with --foxglove and one client: {100 * share1:.1f} % steady "
          f"({100 * whole1:.1f} % whole); added {100 * (share1 - share0):+.1f} points")  # fmt: skip
    print(f"  {live}")
    print(f"  client got {gauges['count']} /gauges messages for {len(rec.gauges)} recorded "
          f"samples (every one, in order: {every}); lost {rec.lost_samples}")  # fmt: skip
    print(f"  sample → client latency: p50 {p50:.2f} ms, p99 {p99:.2f} ms, max {worst:.1f} ms")
    print(f"  (Node client and simulated stands: {node_cpu:.1f} s CPU together; "
          f"load average {os.getloadavg()[0]:.1f})")  # fmt: skip
    if not re.search(r"dropped 0\b", live):
        print("  note: the viewer feed dropped items")


def cli() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--minutes", type=float, default=2.0, help="each run's length")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        bench(args.minutes, Path(folder))


if __name__ == "__main__":
    cli()
