"""End to end: a real ``labstand run --backend sim --foxglove`` and an independent client.

The client (``@foxglove/ws-protocol`` in Node) must see every recorded gauge sample, in
sequence, the model beside it at every sample, and the events as ``foxglove.Log``; a
client that connects, subscribes and then never reads must cost the recording nothing.
"""

from __future__ import annotations

import socket
from collections.abc import Callable
from pathlib import Path

import numpy as np

from recordings import open_recording
from tests.live.conftest import NodeClient, read_url
from tests.run.conftest import SHORT, Outcome, RunProcess, labstand_process


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def _start(run_process: Callable[[list[str]], RunProcess], out: Path, port: int) -> RunProcess:
    proc = run_process([*SHORT, "-o", str(out), "--foxglove", str(port)])
    assert proc.process.stdout is not None
    assert read_url(proc.process.stdout, proc.lines) == f"ws://127.0.0.1:{port}"
    return proc


def test_client_receives_every_sample_and_the_model(
    run_process: Callable[[list[str]], RunProcess],
    node_client: type[NodeClient],
    tmp_path: Path,
) -> None:
    out = tmp_path / "run.mcap"
    port = _free_port()
    # the client first (it retries until the server listens): subscribed before the run
    # records its first sample, which takes the simulated stand's start-up (> 1 s)
    client = node_client(f"ws://127.0.0.1:{port}")
    proc = _start(run_process, out, port)  # loopback by default
    report = client.finish()
    result = proc.finish()
    assert result.code == 0, result.err
    assert "viewer dropped 0" in result.out

    rec = open_recording(out)
    assert rec.lost_samples == 0
    topics = report["topics"]
    assert report["protocol"] in {"foxglove.sdk.v1", "foxglove.websocket.v1"}
    gauges = topics["/gauges"]
    # every recorded sample, once, in order, with the file's sequence numbers and times
    assert gauges["seq"] == rec.gauges["seq"].tolist()
    assert gauges["tNs"] == rec.gauges["t_ns"].tolist()
    assert np.all(np.diff(gauges["seq"]) == 1)
    # log times: the sample times on a wall-clock epoch that only ever moves earlier (the
    # least-delayed arrival so far)
    log_times = np.array([int(t) for t in gauges["logTimes"]], dtype=np.int64)
    epoch = log_times - rec.gauges["t_ns"]
    assert np.all(np.diff(epoch) <= 0)
    # the model beside the measurement, at every sample; the residual small on the
    # simulated stand without effects (it runs the same model)
    for topic in ("/model", "/model/residual"):
        assert topics[topic]["count"] == len(rec.gauges)
        assert topics[topic]["tNs"] == rec.gauges["t_ns"].tolist()
    assert topics["/model/residual"]["schemaName"] == "labstand.ModelResidual"
    # the simulated stand runs the model itself: measured − model is the gauge noise
    # (σ 0.02 N) and the gauges' resolution, while F swings by tens of newtons
    assert topics["/gauges"]["maxAbs"]["force_n"] > 60
    assert topics["/model/residual"]["maxAbs"]["force_n"] < 0.5
    assert topics["/events"]["schemaName"] == "foxglove.Log"
    assert topics["/events"]["count"] == len(rec.events_array)
    assert topics["/drive"]["count"] == len(rec.drive)
    assert topics["/command"]["count"] >= len(rec.gauges) // 10


def test_the_residual_shows_an_effect_the_model_lacks(
    run_process: Callable[[list[str]], RunProcess],
    node_client: type[NodeClient],
    tmp_path: Path,
) -> None:
    port = _free_port()
    client = node_client(f"ws://127.0.0.1:{port}")
    proc = run_process(
        [*SHORT, "--effect", "fibre_viscoelastic", "-o", str(tmp_path / "r.mcap"),
         "--foxglove", str(port)]
    )  # fmt: skip
    report = client.finish()
    result = proc.finish()
    assert result.code == 0, result.err
    # a Maxwell branch in the fibre: the force departs from the baseline while it runs
    assert report["topics"]["/model/residual"]["maxAbs"]["force_n"] > 2.0


def test_a_stalled_client_costs_the_recording_nothing(
    run_process: Callable[[list[str]], RunProcess],
    node_client: type[NodeClient],
    tmp_path: Path,
) -> None:
    out = tmp_path / "run.mcap"
    port = _free_port()
    url = f"ws://127.0.0.1:{port}"
    stalled = node_client(url, stall_s=60)
    reader = node_client(url)
    proc = _start(run_process, out, port)
    assert stalled.wait_line()["stalled"] is True  # subscribed, then never reads
    report = reader.finish()
    result = proc.finish()
    assert result.code == 0, result.err
    assert "0 lost, 0 corrupt" in result.out
    rec = open_recording(out)
    assert rec.lost_samples == 0
    assert np.all(np.diff(rec.gauges["seq"]) == 1)
    # the reading client is not held back by the stalled one
    assert report["topics"]["/gauges"]["seq"] == rec.gauges["seq"].tolist()


# As a child process: the SDK's runtime (its threads, its epoll) lives as long as the
# process that first started a server, so not in the test's.
def test_busy_port_is_bad_input(tmp_path: Path) -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        result = labstand_process("run", *SHORT, "-o", tmp_path / "r.mcap", "--foxglove", str(port))
    assert result.code == 2
    assert result.last_error_line.startswith(f"labstand: error: --foxglove 127.0.0.1:{port}:")
    assert "in use" in result.last_error_line
    assert len(result.err.strip().splitlines()) == 1
    assert not (tmp_path / "r.mcap").exists()  # nothing started, nothing recorded


def test_unreachable_address_is_bad_input(tmp_path: Path) -> None:
    # 192.0.2.1 (TEST-NET-1) is no address of this machine
    result = labstand_process("run", *SHORT, "-o", tmp_path / "r.mcap", "--foxglove", "192.0.2.1:0")
    assert result.code == 2
    assert "--foxglove 192.0.2.1:0:" in result.last_error_line
    assert "open to the network" in result.err  # the warning for a non-loopback address
    assert "Traceback" not in result.err
    assert not (tmp_path / "r.mcap").exists()


def test_bad_port_is_a_usage_error(labstand: Callable[..., Outcome], tmp_path: Path) -> None:
    result = labstand("run", *SHORT, "-o", tmp_path / "r.mcap", "--foxglove", "70000")
    assert result.code == 2
    assert result.last_error_line == (
        "labstand: error: --foxglove '70000': port 70000 is out of range 0-65535"
    )
