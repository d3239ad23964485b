"""``labstand stand-sim --foxglove``: what the simulated gauges measure, and the model."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import numpy as np

from tests.live.conftest import NodeClient, read_url


def test_stand_sim_serves_its_measurements_and_the_model(node_client: type[NodeClient]) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "labstand", "stand-sim", "--foxglove", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        client = node_client(read_url(proc.stdout, []))
        # a second of samples at least, then stop the simulated stand as Ctrl-C would
        for line in proc.stdout:
            if line.startswith("stop with Ctrl-C"):
                break
        time.sleep(1.5)  # not a timing assertion: how long the client watches
        proc.send_signal(signal.SIGTERM)
        report = client.finish()
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    gauges = report["topics"]["/gauges"]
    assert report["server"] == "labstand stand-sim"
    assert gauges["count"] >= 1000
    assert np.all(np.diff(gauges["seq"]) == 1)  # every sample the front end measured
    assert np.all(np.diff(gauges["tNs"]) == 500_000)
    # the baseline beside it; the simulated stand runs the same model (no effect), so
    # the force residual is the gauge noise (σ 0.02 N)
    # (over the span the client watched both: under load its subscriptions land a few
    # milliseconds apart, so one stream may start or end a few samples before the other)
    model = report["topics"]["/model"]["tNs"]
    first, last = max(model[0], gauges["tNs"][0]), min(model[-1], gauges["tNs"][-1])
    assert last - first >= 500_000_000  # half a second of both at least
    assert [t for t in model if first <= t <= last] == [
        t for t in gauges["tNs"] if first <= t <= last
    ]
    assert abs(report["topics"]["/model/residual"]["last"]["force_n"]) < 0.2
