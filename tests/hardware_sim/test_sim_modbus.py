"""The driver against the simulated drive over real Modbus servers: TCP, RTU on ptys."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest

from drivers import unidrive_registers as pr
from drivers.signals import Shape, SignalSpec
from drivers.unidrive import (
    DriveAddressError,
    DriveConnectionError,
    DriveTimeoutError,
    DriveTrippedError,
    UnidriveSP,
    open_unidrive,
)
from drivers.unidrive_profile import ProfileState
from drivers.unidrive_registers import Register, StatusBit, TripCode
from sim.config import StandConfig
from sim.hardware.stand import StandThread
from tests.hardware_sim.conftest import run_stand

SPEC = SignalSpec(Shape.TRAPEZOIDAL, 0.03, 2.0, 1, 0.25, dwell_start_s=0.1, dwell_end_s=0.1)


@pytest.fixture(params=["tcp", "rtu", "socat"])
def link(request: pytest.FixtureRequest, config: StandConfig) -> Iterator[tuple[StandThread, str]]:
    """A running simulated stand and the Modbus URL of its drive."""
    if request.param == "socat":
        server_end, client_end = request.getfixturevalue("socat_pair")
        thread = run_stand(config, modbus=f"rtu:{server_end}")
        thread.start()
        url = f"rtu://{client_end}?baudrate=115200&stopbits=2"
    else:
        thread = run_stand(config, modbus="tcp://127.0.0.1:0" if request.param == "tcp" else "rtu")
        url = thread.start().modbus
    try:
        yield thread, url
    finally:
        thread.stop()


@pytest.fixture
def drive(link: tuple[StandThread, str], config: StandConfig) -> Iterator[UnidriveSP]:
    with open_unidrive(link[1], config.drive, timeout_s=0.5) as d:
        d.check_limits()
        yield d


def test_profile_runs_and_position_follows_the_plan(
    drive: UnidriveSP, link: tuple[StandThread, str]
) -> None:
    delay = link[0].stand.drive.settings.reference_delay_s
    drive.enable()
    state = drive.poll()
    assert state.active and state.status_word & StatusBit.HEALTHY.mask
    profile = drive.load_profile(SPEC)
    drive.start()
    running = []
    deadline = time.monotonic() + profile.duration_s + 3.0
    while time.monotonic() < deadline:
        state = drive.poll()
        if state.profile_state is ProfileState.RUNNING:
            running.append(state)
        if state.profile_state is not ProfileState.RUNNING and running:
            break
        time.sleep(0.02)
    assert state.profile_state is ProfileState.DONE and not state.tripped
    assert len(running) >= 10
    for s in running:  # position and profile time come from the same instant in the drive
        expected = float(profile.position_m(s.profile_time_s - delay))
        assert s.position_m == pytest.approx(expected, abs=0.1e-3)
    assert max(s.position_m for s in running) > 0.02
    assert state.position_m == pytest.approx(0.0, abs=1e-5)
    drive.disable()
    assert not drive.poll().active


def test_trip_reset_and_named_exceptions(drive: UnidriveSP) -> None:
    drive.enable()
    drive.write_raw([pr.USER_TRIP], [47])
    assert drive.poll().trip_code == 47
    with pytest.raises(DriveTrippedError):
        drive.enable()
    drive.reset_trip()
    assert drive.poll().healthy
    with pytest.raises(DriveAddressError, match=r"Pr 20\.21 .*exception 2"):
        drive.read_raw([pr.by_parameter(20, p) for p in range(21, 30)])  # 18 registers
    with pytest.raises(DriveAddressError, match=r"Pr 5\.01 \(motor frequency\)"):
        drive.read(Register(5, 1, 16, 1, "", pr.Access.RO, "motor frequency"))


def test_watchdog_trips_when_the_controller_stops(drive: UnidriveSP) -> None:
    drive.enable()
    for _ in range(10):
        drive.poll()
        time.sleep(0.05)
    last_poll = time.monotonic()
    trip = 0
    while time.monotonic() - last_poll < 3.0 and not trip:
        trip = int(drive.read_raw([pr.TRIP_CODE])[0])  # reading does not toggle the bit
        time.sleep(0.02)
    waited = time.monotonic() - last_poll
    assert trip == TripCode.WATCHDOG
    assert 0.9 < waited < 1.6
    assert not drive.poll().active


def test_a_silent_drive_is_a_timeout_and_the_link_recovers(
    drive: UnidriveSP, link: tuple[StandThread, str]
) -> None:
    thread = link[0]
    assert drive.poll().healthy
    thread.call(lambda: setattr(thread.stand, "modbus_muted", True))
    t0 = time.monotonic()
    with pytest.raises(DriveTimeoutError, match="no reply after 3 attempts"):
        drive.poll()
    assert time.monotonic() - t0 < 3 * 0.5 + 1.0  # three attempts of 0.5 s, no more
    thread.call(lambda: setattr(thread.stand, "modbus_muted", False))
    deadline = time.monotonic() + 5
    while True:  # late replies to the timed-out requests are skipped by the client
        try:
            assert drive.poll().healthy
            break
        except DriveTimeoutError:
            assert time.monotonic() < deadline


def test_a_vanished_server(config: StandConfig) -> None:
    thread = run_stand(config)
    url = thread.start().modbus
    try:
        with open_unidrive(url, config.drive, timeout_s=0.2, retries=1) as d:
            assert d.poll().healthy
            thread.stop()  # the stand's server goes away mid-session
            with pytest.raises((DriveTimeoutError, DriveConnectionError)):
                d.poll()
    finally:
        thread.stop()
