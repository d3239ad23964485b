"""Faults during ``labstand run --backend sim``: each ends with the drive disabled, the
recording readable, one clear line and the right exit code.

Faults come from the real simulated stand: a Modbus write by an independent client
(mbpoll) for the trip, the stand's own fault hook (``--sim-fault``, passed to
``labstand stand-sim --fault``, sim/hardware/faults.py) for the rest, and SIGKILL.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from pymodbus.client import ModbusTcpClient

from labstand.errors import ExitCode
from recordings import Recording, open_recording
from tests.run.conftest import SHORT, Outcome, RunProcess, gone, wait_for

TRIP_CODE, USER_TRIP = 1019, 1037  # Pr 10.20, Pr 10.38 (0-based, HARDWARE.md)


def readable(path: Path) -> Recording:
    """The recording opens without repair and its gauges are contiguous."""
    rec = open_recording(path)
    assert len(rec.gauges) > 0 and rec.lost_samples == 0
    return rec


def ends_disabled(rec: Recording) -> None:
    """The last drive poll shows the output off."""
    assert len(rec.drive) > 0 and not rec.drive["enabled"][-1]


def estop_events(rec: Recording) -> list[str]:
    events = rec.events()
    return list(events.loc[events["kind"] == "estop", "text"])


def test_drive_tripped_by_an_independent_modbus_write(
    run_process: Callable[[list[str]], RunProcess], tmp_path: Path
) -> None:
    if shutil.which("mbpoll") is None:
        pytest.fail("mbpoll is not installed (make system-tools installs it)")
    out = tmp_path / "trip.mcap"
    run = run_process([*SHORT, "-o", str(out)])
    run.wait_endpoints()
    wait_for(out.exists, 30.0, "the recording to start")
    time.sleep(0.8)  # into the first cycle
    cmd = ["mbpoll", "-m", "tcp", "-p", str(run.modbus_port), "-a", "1", "-0", "-1", "-t", "4"]
    write = subprocess.run(
        [*cmd, "-r", str(USER_TRIP), "127.0.0.1", "--", "45"],
        capture_output=True, text=True, timeout=15, check=False,
    )  # fmt: skip
    assert write.returncode == 0, write.stdout + write.stderr
    result = run.finish()
    assert result.code == ExitCode.ESTOP, result.err
    assert result.last_error_line.startswith("labstand: e-stop: the drive tripped: trip 45;")
    assert "drive disabled" in result.last_error_line
    rec = readable(out)
    ends_disabled(rec)
    assert rec.drive["trip_code"][-1] == 45
    assert estop_events(rec) == ["the drive tripped: trip 45"]


@pytest.mark.parametrize(
    ("fault", "message"),
    [
        ("gauges-silent@0.5", "the gauge stream has been silent for 0.2"),
        ("modbus-mute@0.5", "the drive did not answer: "),
    ],
)
def test_a_device_that_stops_answering_is_an_estop(
    labstand: Callable[..., Outcome], tmp_path: Path, fault: str, message: str
) -> None:
    out = tmp_path / "fault.h5"
    result = labstand("run", *SHORT, "--sim-fault", fault, "-o", out)
    assert result.code == ExitCode.ESTOP, result.err
    line = result.last_error_line
    assert line.startswith(f"labstand: e-stop: {message}"), line
    rec = readable(out)
    assert len(estop_events(rec)) == 1
    events = rec.events()
    final = events.loc[events["kind"] == "note", "text"].iloc[-1]
    assert final.startswith("simulated stand stopped: drive disabled")
    if fault.startswith("gauges"):
        ends_disabled(rec)
        assert "; drive disabled;" in line
    else:  # the drive could not be told: its watchdog stopped it (trip 30)
        assert "the simulated drive reports itself disabled, trips [30]" in line
        assert "trips [30]" in final


def test_garbage_on_the_gauge_line_is_counted_and_the_run_goes_on(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    out = tmp_path / "garbage.mcap"
    result = labstand("run", *SHORT, "--sim-fault", "garbage@0.5:300", "-o", out)
    assert result.code == 0, result.err
    assert "0 lost, 1 corrupt" in result.out
    rec = readable(out)
    ends_disabled(rec)
    assert np.all(np.diff(rec.gauges["seq"]) == 1)
    faults = list(rec.events().query("kind == 'fault'")["text"])
    assert faults == [
        "gauges: 1 corrupt section(s) (300 bytes skipped), 0 frame(s) lost; the run goes on"
    ]


def test_a_flung_weight_is_an_estop(labstand: Callable[..., Outcome], tmp_path: Path) -> None:
    # rectangular 30 mm steps at 2 Hz fling the heavy weight: slack for ≈ 0.37 s. The
    # safety prediction refuses it before moving; overridden, the e-stop must catch it.
    out = tmp_path / "flung.mcap"
    args = ["--signal", "rectangular", "--amplitude-mm", "30", "--frequency-hz", "2"]
    result = labstand("run", *SHORT, *args, "--override-prediction", "-o", out)
    assert result.code == ExitCode.ESTOP, result.err
    assert "labstand: warning: prediction overridden: weight travel" in result.err
    assert result.last_error_line.startswith("labstand: e-stop: fibre slack (F < 2 N) for 0.2")
    rec = readable(out)
    ends_disabled(rec)
    assert estop_events(rec)[0].startswith("fibre slack")


@pytest.mark.parametrize("presses", [1, 2])
def test_ctrl_c(
    labstand: Callable[..., Outcome],
    ctrl_c: Callable[[Path, float, int], None],
    tmp_path: Path,
    presses: int,
) -> None:
    out = tmp_path / "ctrl-c.mcap"
    ctrl_c(out, 1.0, presses)
    result = labstand("run", *SHORT, "-o", out)
    assert result.code == ExitCode.INTERRUPTED, result.err
    line = result.last_error_line
    what = "controlled stop" if presses == 1 else "immediate disable"
    assert line.startswith("labstand: interrupted: Ctrl-C") and what in line, line
    rec = readable(out)
    ends_disabled(rec)
    kinds = list(rec.events()["kind"])
    if presses == 1:  # came to rest under control, where it stood
        assert kinds[:2] == ["start", "stop"] and "estop" not in kinds
        assert abs(rec.drive["speed_mm_s"][-1]) < 1.0
    else:  # the second press may come before the first was acted on: no "stop" then
        assert kinds[0] == "start" and estop_events(rec)[0].endswith("immediate disable")


def test_sigkill_trips_the_watchdog_and_the_recording_recovers(
    run_process: Callable[[list[str]], RunProcess],
    labstand: Callable[..., Outcome],
    tmp_path: Path,
) -> None:
    out = tmp_path / "killed.mcap"
    run = run_process([*SHORT, "--cycles", "5", "-o", str(out)])
    run.wait_endpoints()
    wait_for(out.exists, 30.0, "the recording to start")
    opened = time.monotonic()
    time.sleep(2.0)
    os.kill(run.process.pid, signal.SIGKILL)
    killed = time.monotonic()
    run.process.wait(10)

    client = ModbusTcpClient("127.0.0.1", port=run.modbus_port, timeout=0.5)
    try:
        assert client.connect()

        def tripped() -> bool:
            reply = client.read_holding_registers(TRIP_CODE, count=1, device_id=1)
            return not reply.isError() and reply.registers[0] == 30  # watchdog

        wait_for(tripped, 2.0, "the simulated drive's watchdog trip")
        assert time.monotonic() - killed < 1.5
    finally:
        client.close()
    wait_for(lambda: gone(run.sim_pid), 6.0, "the simulated stand to exit")

    with pytest.raises(Exception, match="labstand recover"):
        open_recording(out)
    fixed = tmp_path / "fixed.mcap"
    result = labstand("recover", out, "-o", fixed)
    assert result.code == 0, result.err
    rec = open_recording(fixed)
    assert np.all(np.diff(rec.gauges["seq"]) == 1)
    # at most about a second lost: the writer flushes every 0.5 s
    assert rec.duration_s > (killed - opened) - 1.2
