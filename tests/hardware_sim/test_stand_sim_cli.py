"""``labstand stand-sim`` as a process: endpoints, reachability, clean stops, orphan exit."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from drivers.gauge_stream import SerialGaugeStream
from drivers.unidrive import open_unidrive
from labstand.cli import main
from sim.config import StandConfig
from sim.hardware.process import StandProcess, wait_exit
from tests.hardware_sim.leakcheck import gone


def test_endpoints_are_reachable_and_sigterm_stops_cleanly(config: StandConfig) -> None:
    sim = StandProcess(["--mass-kg", "3.096"])
    ep = sim.start()
    try:
        assert ep["event"] == "ready" and ep["pid"] == sim.process.pid  # type: ignore[union-attr]
        assert ep["modbus"].startswith("tcp://127.0.0.1:")
        assert (ep["rate_hz"], ep["frame_bytes"], ep["frame_version"]) == (2000.0, 24, 1)
        with open_unidrive(ep["modbus"], config.drive) as drive:
            assert drive.poll().healthy
        with SerialGaugeStream(ep["gauges"], config.gauges) as gauges:
            block = gauges.read_block(2.0)
            assert block is not None and len(block) > 0
            # at rest the force is the static preload of the light weight
            params = config.stand_params("final", 3.096)
            assert block["force_n"].mean() == pytest.approx(params.preload_tension_n, abs=0.1)
    finally:
        t0 = time.monotonic()
        code = sim.stop()
    assert code == 0
    assert time.monotonic() - t0 < 3.0
    assert sim.stopped["event"] == "stopped" and sim.stopped["frames"] > 0
    assert not Path(ep["gauges"]).exists()
    port = int(ep["modbus"].rsplit(":", 1)[1])
    with pytest.raises(ConnectionRefusedError), socket.create_connection(("127.0.0.1", port), 1):
        pass


def test_rtu_endpoint_and_ctrl_c(config: StandConfig) -> None:
    sim = StandProcess(["--modbus", "rtu"])
    ep = sim.start()
    try:
        assert ep["modbus"].startswith("rtu:///dev/pts/")
        with open_unidrive(ep["modbus"], config.drive) as drive:
            assert drive.poll().healthy
        sim.process.send_signal(signal.SIGINT)  # type: ignore[union-attr]
        assert wait_exit(sim.process, 3.0) == 0  # type: ignore[arg-type]
    finally:
        sim.stop()


def test_exits_when_its_parent_is_killed() -> None:
    parent_code = (  # a light stand-in for labstand run: starts the stand as StandProcess does
        "import os, subprocess, sys, time\n"
        "cmd = [sys.executable, '-m', 'labstand', 'stand-sim', '--json',\n"
        "       '--parent-pid', str(os.getpid())]\n"
        "child = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)\n"
        "print(child.stdout.readline(), end='', flush=True)\n"
        "time.sleep(120)\n"
    )
    parent = subprocess.Popen(
        [sys.executable, "-c", parent_code], stdout=subprocess.PIPE, text=True
    )
    try:
        assert parent.stdout is not None
        line = parent.stdout.readline()
        child = json.loads(line)["pid"]
        assert not gone(child)
        os.kill(parent.pid, signal.SIGKILL)  # labstand dies without cleaning up
        parent.wait(5)
        deadline = time.monotonic() + 3.0
        while not gone(child) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert gone(child), "the simulated stand outlived its parent"
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()
        if parent.stdout is not None:
            parent.stdout.close()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--effect", "no_such_effect"], "unknown effect 'no_such_effect'"),
        (["--modbus", "tcp://0.0.0.0:0"], "loopback only"),
        (["--modbus", "serial"], "--modbus must be"),
        (["--speed", "0"], "clock speed must be > 0"),
    ],
)
def test_bad_options_are_one_line_errors(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["stand-sim", *args]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_port_in_use_is_a_clear_failure(capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["stand-sim", "--modbus", f"tcp://127.0.0.1:{port}"]) == 1
    assert f"cannot listen on 127.0.0.1:{port}" in capsys.readouterr().err
