"""The simulated drive as an independent Modbus client sees it: Debian's mbpoll."""

from __future__ import annotations

import re
import shutil
import subprocess
from collections.abc import Iterator

import pytest

from drivers import unidrive_registers as pr
from sim.config import StandConfig
from sim.hardware.stand import StandThread
from tests.hardware_sim.conftest import run_stand

# 0-based 16-bit addresses of HARDWARE.md; 16504 is the 32-bit address of Pr 1.21.
TRIP_CODE, STATUS_WORD, CONTROL_WORD, CW_ENABLE, USER_TRIP = 1019, 1039, 641, 642, 1037
SPEED_REF_32 = 16504
HEALTHY, ACTIVE = 1 << 0, 1 << 1


class Mbpoll:
    """mbpoll with HARDWARE.md's options (``-0``: 0-based ``-r``; one poll with ``-1``)."""

    def __init__(self, options: list[str], target: str) -> None:
        if shutil.which("mbpoll") is None:
            pytest.fail("mbpoll is not installed (make system-tools installs it)")
        self.options, self.target = options, target

    def run(self, register: int, *values: int, kind: str = "4", count: int = 1):  # type: ignore[no-untyped-def]
        cmd = ["mbpoll", *self.options, "-a", "1", "-0", "-1", "-t", kind, "-r", str(register)]
        if kind == "4:int":
            cmd.append("-B")  # 32-bit values high word first, as the drive sends them
        if not values:
            cmd += ["-c", str(count)]
        cmd.append(self.target)
        if values:
            cmd += ["--", *map(str, values)]
        return subprocess.run(cmd, capture_output=True, text=True, timeout=15, check=False)

    def read(self, register: int, kind: str = "4", count: int = 1) -> list[int]:
        out = self.run(register, kind=kind, count=count)
        assert out.returncode == 0, out.stderr
        return [int(v) for v in re.findall(r"^\[\d+\]:\s+(-?\d+)", out.stdout, re.M)]

    def write(self, register: int, *values: int, kind: str = "4") -> None:
        out = self.run(register, *values, kind=kind)
        assert out.returncode == 0, out.stderr
        assert "Written" in out.stdout


@pytest.fixture(params=["tcp", "rtu-socat"])
def mbpoll(
    request: pytest.FixtureRequest, config: StandConfig
) -> Iterator[tuple[Mbpoll, StandThread]]:
    if request.param == "tcp":
        thread = run_stand(config)
        port = thread.start().modbus.rsplit(":", 1)[1]
        mb = Mbpoll(["-m", "tcp", "-p", port], "127.0.0.1")
    else:
        server_end, client_end = request.getfixturevalue("socat_pair")
        thread = run_stand(config, modbus=f"rtu:{server_end}")
        thread.start()
        mb = Mbpoll(["-m", "rtu", "-b", "115200", "-d", "8", "-P", "none", "-s", "2"], client_end)
    try:
        yield mb, thread
    finally:
        thread.stop()


def test_mbpoll_reads_trip_and_status_and_commands_the_drive(
    mbpoll: tuple[Mbpoll, StandThread],
) -> None:
    mb, thread = mbpoll
    assert mb.read(TRIP_CODE) == [0]
    status = mb.read(STATUS_WORD)[0]
    assert status & HEALTHY and not status & ACTIVE
    mb.write(CW_ENABLE, 1)
    mb.write(CONTROL_WORD, 129)  # "129 enabled" (HARDWARE.md)
    assert mb.read(STATUS_WORD)[0] & ACTIVE
    assert thread.call(lambda: thread.stand.drive.enabled)
    mb.write(CONTROL_WORD, 128 | 1 << 12)  # control-word trip
    assert mb.read(TRIP_CODE) == [52]
    assert not mb.read(STATUS_WORD)[0] & (HEALTHY | ACTIVE)
    mb.write(USER_TRIP, 100)  # reset
    assert mb.read(TRIP_CODE) == [0]
    assert mb.read(STATUS_WORD)[0] & HEALTHY


def test_mbpoll_32bit_parameter_and_exception_2(mbpoll: tuple[Mbpoll, StandThread]) -> None:
    mb, thread = mbpoll
    mb.write(SPEED_REF_32, -15000, kind="4:int")
    assert mb.read(SPEED_REF_32, kind="4:int") == [-15000]
    assert thread.call(lambda: thread.stand.drive.params[pr.SPEED_REFERENCE]) == -15000
    assert mb.read(SPEED_REF_32, count=2) == [65535, 50536]  # raw words, high first
    for register, count in ((1000, 17), (400, 1)):  # > 16 registers; unknown Pr 4.01
        out = mb.run(register, count=count)
        assert out.returncode == 1
        assert "Illegal data address" in out.stderr
