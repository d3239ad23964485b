"""Run after run at a stand that stays up: an orderly end leaves the drive healthy.

One ``labstand stand-sim`` process plays the stand that is always on (Modbus TCP on
127.0.0.1, the gauges on a raw pty); a stand file's ``[devices]`` table points
``labstand run --backend stand --yes`` at it. Between runs an independent Modbus client
(plain pymodbus, not labstand's driver; reads only, so it toggles no watchdog) waits
until more than the watchdog's second of drive time has passed without labstand, then
reads Pr 10.20: a drive left to its watchdog would have tripped (trip 30) by then.

Stops labstand decides (an e-stop, Ctrl-C) leave the drive healthy too; a labstand killed
while in control leaves trip 30, which the next pre-flight names and refuses.
"""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from pymodbus.client import ModbusTcpClient

from drivers import unidrive_registers as pr
from drivers.unidrive_registers import TripCode
from labstand.errors import ExitCode
from sim.hardware.process import StandProcess
from tests.run.conftest import Outcome, wait_for

#: A short run: 0.1 s rest, one 10 mm trapezoid at 2 Hz, 0.1 s rest (0.7 s of motion).
BRIEF = [
    "--backend", "stand", "--yes", "--signal", "trapezoidal", "--amplitude-mm", "10",
    "--frequency-hz", "2", "--cycles", "1", "--dwell-start-s", "0.1", "--dwell-end-s", "0.1",
]  # fmt: skip
#: The drive's watchdog trips 1 s after the last edge; wait this much drive time.
QUIET_S = 1.2


class Observer:
    """Reads the simulated drive over Modbus TCP like any other client would."""

    def __init__(self, port: int) -> None:
        self.client = ModbusTcpClient("127.0.0.1", port=port, timeout=1.0)
        assert self.client.connect()

    def read(self, reg: pr.Register) -> int:
        reply = self.client.read_holding_registers(reg.address, count=reg.count, device_id=1)
        assert not reply.isError(), reply
        words = reply.registers
        return words[0] if reg.count == 1 else (words[0] << 16) | words[1]

    def trip_after_quiet(self) -> int:
        """Pr 10.20 once QUIET_S of drive time has passed (read on the drive's own clock)."""
        start_ms = self.read(pr.DRIVE_CLOCK)
        wait_for(
            lambda: self.read(pr.DRIVE_CLOCK) - start_ms > QUIET_S * 1e3,
            10.0,
            f"{QUIET_S:g} s of drive time",
        )
        return self.read(pr.TRIP_CODE)

    def write(self, reg: pr.Register, value: int) -> None:
        reply = self.client.write_register(reg.address, value, device_id=1)
        assert not reply.isError(), reply


@pytest.fixture
def standing_stand(tmp_path: Path) -> Iterator[tuple[Path, Observer]]:
    """A simulated stand that stays up, and a stand file whose [devices] name it."""
    with StandProcess() as sim:
        ep = sim.endpoints
        stand = tmp_path / "stand.toml"
        stand.write_text(f'[devices]\ndrive = "{ep["modbus"]}"\ngauges = "{ep["gauges"]}"\n')
        observer = Observer(int(ep["modbus"].rsplit(":", 1)[1]))
        try:
            yield stand, observer
        finally:
            observer.client.close()
    assert sim.stopped.get("event") == "stopped"


def test_ten_runs_then_a_fault_a_refusal_and_a_reset(
    labstand: Callable[..., Outcome],
    standing_stand: tuple[Path, Observer],
    tmp_path: Path,
) -> None:
    stand, drive = standing_stand

    def run(name: str, *extra: str) -> Outcome:
        return labstand("run", *BRIEF, "--stand", stand, *extra, "-o", tmp_path / name)

    for i in range(10):
        result = run(f"run{i}.mcap")
        assert result.code == 0, f"run {i + 1}: {result.err}"
        assert "Done: drive disabled;" in result.out
        assert "samples, 0 lost, 0 corrupt)" in result.out  # joining the stream is no fault
        assert drive.trip_after_quiet() == 0, f"the drive tripped after run {i + 1}"
        assert drive.read(pr.STATUS_WORD) & pr.StatusBit.HEALTHY.mask

    # a real fault: the drive trips on its own (a user trip written by another client)
    out = tmp_path / "fault.mcap"

    def trip_when_recording() -> None:
        wait_for(out.exists, 30.0, "the faulted run to record")
        drive.write(pr.USER_TRIP, 45)

    tripper = threading.Thread(target=trip_when_recording, name="test tripper")
    tripper.start()
    try:
        result = run("fault.mcap")
    finally:
        tripper.join(35.0)
    assert result.code == ExitCode.ESTOP, result.err
    assert result.last_error_line.startswith("labstand: e-stop: the drive tripped: trip 45;")
    assert drive.trip_after_quiet() == 45  # labstand left the drive's own trip alone

    result = run("refused.mcap")
    assert result.code == ExitCode.REFUSED, result.err
    assert result.last_error_line.endswith(
        "is tripped: trip 45; find the cause, then run again with --reset-trip"
    )
    assert not (tmp_path / "refused.mcap").exists()

    result = run("reset.mcap", "--reset-trip")
    assert result.code == 0, result.err
    assert drive.trip_after_quiet() == 0


def test_stops_labstand_decides_leave_it_healthy_and_a_killed_run_leaves_trip_30(
    labstand: Callable[..., Outcome],
    ctrl_c: Callable[[Path, float, int], None],
    standing_stand: tuple[Path, Observer],
    tmp_path: Path,
) -> None:
    stand, drive = standing_stand

    def run(name: str, *extra: str) -> Outcome:
        return labstand("run", *BRIEF, "--stand", stand, *extra, "-o", tmp_path / name)

    # an e-stop labstand decides (the weight is flung: slack): disabled, stood down
    # (the safety prediction refuses it before moving: overridden, to reach the e-stop)
    fling = ["--signal", "rectangular", "--amplitude-mm", "30", "--cycles", "2"]
    fling.append("--override-prediction")
    result = run("flung.mcap", *fling)
    assert result.code == ExitCode.ESTOP, result.err
    assert result.last_error_line.startswith("labstand: e-stop: fibre slack")
    assert drive.trip_after_quiet() == 0

    out = tmp_path / "ctrl-c.mcap"
    ctrl_c(out, 0.3, 1)
    result = run("ctrl-c.mcap", "--cycles", "3")
    assert result.code == ExitCode.INTERRUPTED, result.err
    assert drive.trip_after_quiet() == 0

    # labstand killed while in control: the drive trips on its watchdog, and stays so
    killed = tmp_path / "killed.mcap"
    args = ["run", *BRIEF, "--cycles", "6", "--stand", str(stand), "-o", str(killed)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "labstand", *args],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        wait_for(killed.exists, 60.0, "the killed run to record")
        time.sleep(0.5)  # into the motion
    finally:
        proc.kill()
        proc.wait(10)
    assert drive.trip_after_quiet() == TripCode.WATCHDOG

    result = run("after-kill.mcap")
    assert result.code == ExitCode.REFUSED, result.err
    assert "is tripped: trip 30 (watchdog: the controller stopped toggling it while in " in (
        result.last_error_line
    )
    assert "a killed labstand or a lost link)" in result.last_error_line
    result = run("recovered.mcap", "--reset-trip")
    assert result.code == 0, result.err
    assert drive.trip_after_quiet() == 0
