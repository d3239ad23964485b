"""What every ``DriveInterface`` backend must do, run against each (conftest.drive_rig).

The same file proves the simulated drive over Modbus TCP and RTU and, marked
``hardware``, the real Unidrive SP. No test moves the axis: the behaviours are those
that keep the stand safe and make run after run possible.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator

import pytest

from drivers.errors import ClosedError, DeviceTimeoutError, DriveError, DriveNotReadyError
from drivers.interfaces import DriveInterface, DriveState
from drivers.limits import DriveLimits, LimitError
from drivers.signals import Shape, SignalSpec
from drivers.unidrive_profile import ProfileState
from drivers.unidrive_registers import TripCode
from tests.contract.conftest import DriveRig

#: The watchdog trips 1 s after the last edge; wait a margin beyond it.
WATCHDOG_QUIET_S = 1.5


def _healthy(rig: DriveRig) -> None:
    """Leave the drive answering, untripped and stood down."""
    if rig.mute is not None:
        rig.mute(False)
    with rig.open() as drive:
        if drive.poll().tripped:
            drive.reset_trip()


@pytest.fixture
def drive(drive_rig: DriveRig) -> Iterator[DriveInterface]:
    """A fresh connection to a healthy drive; the drive is left healthy afterwards."""
    _healthy(drive_rig)
    d = drive_rig.open()
    try:
        yield d
    finally:
        d.close()
        _healthy(drive_rig)


def _ready(drive: DriveInterface) -> DriveInterface:
    drive.check_limits()
    return drive


def test_connects_and_identifies(drive: DriveInterface) -> None:
    assert isinstance(drive, DriveInterface) and drive.name
    first = drive.poll()
    assert isinstance(first, DriveState)
    assert first.healthy and not first.tripped and not first.active
    second = drive.poll()
    assert second.drive_clock_s >= first.drive_clock_s  # one clock, read twice
    theirs = drive.check_limits()
    assert isinstance(theirs, DriveLimits)
    assert drive.limits.speed_max_m_s <= theirs.speed_max_m_s * (1 + 1e-6)


def test_enable_is_refused_before_the_limits_are_checked(drive: DriveInterface) -> None:
    with pytest.raises(DriveNotReadyError, match="limits were not checked"):
        drive.enable()
    assert not drive.poll().active


def test_enable_is_refused_on_a_tripped_drive(drive: DriveInterface) -> None:
    _ready(drive)
    _user_trip(drive, 45)
    state = drive.poll()
    assert state.tripped and state.trip_code == 45 and not state.healthy
    with pytest.raises(DriveError, match="trip 45"):
        drive.enable()
    assert not drive.poll().active
    drive.reset_trip()
    state = drive.poll()
    assert state.healthy and not state.active  # a reset leaves it disabled


@pytest.mark.parametrize(
    "spec",
    [
        SignalSpec(Shape.TRAPEZOIDAL, 0.2, 1.0, 1),  # stroke beyond 90 mm
        SignalSpec(Shape.QUASI_SINUSOIDAL, 0.06, 3.0, 1),  # ≈ 10.7 m/s² > 10
        SignalSpec(Shape.RECTANGULAR, 0.08, 5.0, 1),  # speed and acceleration
    ],
    ids=["amplitude", "acceleration", "speed"],
)
def test_limits_refuse_out_of_range_commands_without_moving(
    drive: DriveInterface, spec: SignalSpec
) -> None:
    _ready(drive).enable()
    before = _until_active(drive)
    with pytest.raises(LimitError):
        drive.load_profile(spec)
    drive.start()  # nothing armed: RUN FWD must not move the axis
    after = drive.poll()
    assert after.profile_state is before.profile_state
    assert after.profile_state is not ProfileState.RUNNING
    assert abs(after.position_m - before.position_m) < 0.05e-3
    assert abs(after.velocity_m_s) < 1e-3
    drive.stand_down()


def test_disable_always_works_and_is_idempotent(drive: DriveInterface) -> None:
    drive.disable()  # never enabled
    drive.disable()
    assert not drive.poll().active
    _ready(drive).enable()
    _until_active(drive)
    drive.disable()
    drive.disable()
    assert not drive.poll().active
    _user_trip(drive, 46)
    drive.disable()  # also on a tripped drive
    drive.stand_down()
    drive.stand_down()
    assert not drive.poll().active


def test_watchdog_stand_down_leaves_the_drive_healthy(
    drive: DriveInterface, drive_rig: DriveRig
) -> None:
    _ready(drive).enable()
    _until_active(drive)
    drive.poll()
    drive.stand_down()
    drive_rig.quiet(WATCHDOG_QUIET_S)  # no polls, no toggles
    state = drive.poll()
    assert state.healthy and not state.tripped and not state.active
    drive.enable()  # and the next run can enable again
    assert _until_active(drive).active
    drive.stand_down()


def test_a_controller_that_stops_polling_trips_the_watchdog(
    drive: DriveInterface, drive_rig: DriveRig
) -> None:
    _ready(drive).enable()
    _until_active(drive)
    drive_rig.quiet(WATCHDOG_QUIET_S)  # as if labstand had died while in control
    state = drive.poll()
    assert state.trip_code == TripCode.WATCHDOG and not state.active


def test_a_closed_drive_refuses_work(drive: DriveInterface) -> None:
    drive.close()
    drive.close()  # idempotent
    assert drive.closed
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.01, 1.0, 1)
    calls: list[Callable[[], object]] = [
        drive.poll,
        drive.enable,
        drive.disable,
        drive.stand_down,
        drive.check_limits,
        lambda: drive.load_profile(spec),
        drive.start,
        drive.stop,
        drive.home,
        drive.reset_trip,
        drive.kick_watchdog,
        drive.__enter__,
    ]
    for call in calls:
        with pytest.raises(ClosedError, match="closed"):
            call()


def test_a_drive_that_stops_answering_times_out(drive: DriveInterface, drive_rig: DriveRig) -> None:
    if drive_rig.mute is None:
        pytest.skip("the real drive cannot be silenced from here")
    drive.poll()
    drive_rig.mute(True)
    t0 = time.monotonic()
    with pytest.raises(DeviceTimeoutError) as err:
        drive.poll()
    elapsed = time.monotonic() - t0
    assert isinstance(err.value, TimeoutError) and isinstance(err.value, DriveError)
    assert elapsed < drive_rig.timeout_s + 1.0, f"{elapsed:.2f} s"
    drive_rig.mute(False)
    assert drive.poll().healthy  # the link recovers


# ---- helpers -----------------------------------------------------------------------------
def _until_active(drive: DriveInterface, timeout_s: float = 2.0) -> DriveState:
    deadline = time.monotonic() + timeout_s
    while not (state := drive.poll()).active:
        assert time.monotonic() < deadline, "the drive did not enable"
    return state


def _user_trip(drive: DriveInterface, code: int) -> None:
    """A trip from outside: Pr 10.38 = code (every backend here is a Unidrive SP)."""
    from drivers import unidrive_registers as pr
    from drivers.unidrive import UnidriveSP

    assert isinstance(drive, UnidriveSP), "a user trip needs the Unidrive's Pr 10.38"
    drive.write_raw([pr.USER_TRIP], [code])
