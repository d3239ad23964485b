"""The Unidrive SP driver against an in-memory simulated drive: behaviour and errors."""

from __future__ import annotations

import pytest
from pymodbus.exceptions import ConnectionException, ModbusIOException

from drivers import unidrive_registers as pr
from drivers.errors import DriveNotReadyError
from drivers.interfaces import ClosedError, DriveInterface
from drivers.limits import DriveLimits, LimitError
from drivers.signals import Shape, SignalSpec
from drivers.unidrive import (
    DriveAddressError,
    DriveClosedError,
    DriveConnectionError,
    DriveError,
    DriveProfileError,
    DriveReplyError,
    DriveTimeoutError,
    DriveTrippedError,
    DriveValueError,
    UnidriveSP,
    open_unidrive,
)
from drivers.unidrive_profile import ProfileState, RejectReason
from drivers.unidrive_registers import ControlBit, Register, StatusBit, TripCode
from sim.hardware.drive import SimulatedDrive
from sim.hardware.inprocess import InProcessClient

LIMITS = DriveLimits()
RATE = 2000.0
SINE = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.02, 1.0, 1, dwell_start_s=0.1, dwell_end_s=0.1)


@pytest.fixture
def sim() -> SimulatedDrive:
    return SimulatedDrive(LIMITS, RATE)


@pytest.fixture
def client(sim: SimulatedDrive) -> InProcessClient:
    return InProcessClient(sim)


@pytest.fixture
def drive(client: InProcessClient) -> UnidriveSP:
    d = UnidriveSP(client, LIMITS, retries=2)
    d.check_limits()  # the pre-flight step enable() requires
    return d


def run_for(sim: SimulatedDrive, drive: UnidriveSP, seconds: float, poll_hz: float = 20.0) -> None:
    """Advance simulated time, polling like a controller would."""
    step = round(RATE / poll_hz)
    for _ in range(round(seconds * poll_hz)):
        sim.advance(step)
        drive.poll()


def test_is_a_drive_interface(drive: UnidriveSP) -> None:
    assert isinstance(drive, DriveInterface)


def test_poll_reads_the_status_block_and_toggles_the_watchdog(
    drive: UnidriveSP, client: InProcessClient, sim: SimulatedDrive
) -> None:
    state = drive.poll()
    assert state.healthy and not state.active and state.profile_state is ProfileState.IDLE
    assert state.position_m == 0.0
    fc, address, _values = client.requests[-1]
    assert (fc, address) == (23, pr.CONTROL_WORD.address)  # one round trip per poll
    first = sim.params[pr.CONTROL_WORD] & ControlBit.WATCHDOG.mask
    drive.poll()
    assert sim.params[pr.CONTROL_WORD] & ControlBit.WATCHDOG.mask != first


def test_enable_run_profile_done(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    state = drive.poll()
    assert state.active and state.status_word & StatusBit.ACTIVE.mask
    profile = drive.load_profile(SINE)
    assert drive.poll().profile_state is ProfileState.ARMED
    drive.start()
    run_for(sim, drive, 0.6)
    state = drive.poll()
    assert state.profile_state is ProfileState.RUNNING
    delay = sim.settings.reference_delay_s
    expected = float(profile.position_m(state.profile_time_s - delay))
    assert state.position_m == pytest.approx(expected, abs=50e-6)
    assert state.position_m > 0.015
    run_for(sim, drive, profile.duration_s)
    state = drive.poll()
    assert state.profile_state is ProfileState.DONE
    assert state.position_m == pytest.approx(0.0, abs=1e-5)
    assert not state.tripped


def test_stop_decelerates_and_aborts(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    drive.load_profile(SINE)
    drive.start()
    run_for(sim, drive, 0.35)
    moving = drive.poll()
    assert moving.velocity_m_s > 0.01
    drive.stop()
    run_for(sim, drive, 0.2)
    state = drive.poll()
    assert state.profile_state is ProfileState.ABORTED
    assert state.velocity_m_s == pytest.approx(0.0, abs=1e-4)
    assert state.active  # a controlled stop keeps the drive enabled
    drive.home()
    run_for(sim, drive, 0.5)
    assert drive.poll().position_m == pytest.approx(0.0, abs=1e-5)


def test_disable_is_immediate(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    drive.load_profile(SINE)
    drive.start()
    run_for(sim, drive, 0.3)
    drive.disable()
    state = drive.poll()
    assert not state.active and state.profile_state is ProfileState.ABORTED


def test_profiles_beyond_labstands_limits_are_refused_before_writing(
    drive: UnidriveSP, client: InProcessClient
) -> None:
    n = len(client.requests)
    with pytest.raises(LimitError, match="exceeds the drive limit"):
        drive.load_profile(SignalSpec(Shape.QUASI_SINUSOIDAL, 0.09, 3.0, 1))
    assert len(client.requests) == n


def test_drive_program_refusal_is_a_profile_error(sim: SimulatedDrive) -> None:
    # labstand believes in looser limits than the drive was commissioned with
    loose = UnidriveSP(InProcessClient(sim), DriveLimits(0.09, 3.0, 50.0))
    fast = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.06, 3.0, 1)  # 10.7 m/s² > 10
    with pytest.raises(DriveProfileError, match="limits") as err:
        loose.load_profile(fast)
    assert err.value.reason is RejectReason.LIMITS
    with pytest.raises(LimitError, match="speed limit 3 m/s exceeds the drive's"):
        loose.check_limits()


def test_drive_limits_are_read_back(drive: UnidriveSP) -> None:
    limits = drive.check_limits()
    assert limits == LIMITS


def test_enable_is_refused_until_the_limits_were_checked(
    client: InProcessClient, sim: SimulatedDrive
) -> None:
    fresh = UnidriveSP(client, LIMITS)
    with pytest.raises(DriveNotReadyError, match="limits were not checked"):
        fresh.enable()
    assert not sim.enabled and sim.params[pr.CONTROL_WORD_ENABLE] == 0  # nothing written
    loose = UnidriveSP(client, DriveLimits(0.09, 3.0, 50.0))
    with pytest.raises(LimitError):
        loose.check_limits()
    with pytest.raises(DriveNotReadyError):
        loose.enable()  # a failed check does not count
    fresh.check_limits()
    fresh.enable()
    assert sim.enabled


def test_trip_and_reset(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    drive.write_raw([pr.USER_TRIP], [45])
    state = drive.poll()
    assert state.tripped and state.trip_code == 45 and not state.active and not state.healthy
    with pytest.raises(DriveTrippedError, match="trip 45") as err:
        drive.enable()
    assert err.value.trip_code == 45
    drive.reset_trip()
    state = drive.poll()
    assert state.healthy and not state.active  # reset leaves it disabled
    drive.enable()
    assert drive.poll().active


def test_watchdog_trips_when_polling_stops(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    run_for(sim, drive, 2.0, poll_hz=5.0)  # 5 Hz polling: edges every 0.4 s
    assert not drive.poll().tripped
    sim.advance(round(1.2 * RATE))
    state = drive.poll()
    assert state.trip_code == TripCode.WATCHDOG
    assert state.trip_name == "watchdog"


def test_exception_2_names_the_parameter(drive: UnidriveSP) -> None:
    unknown = Register(5, 1, 16, 1, "", pr.Access.RO, "motor frequency")
    with pytest.raises(DriveAddressError, match=r"Pr 5\.01 \(motor frequency\).*exception 2"):
        drive.read(unknown)
    too_many = [pr.by_parameter(20, p) for p in range(21, 30)]  # 18 registers
    with pytest.raises(DriveAddressError, match=r"Pr 20\.21 .* 16 registers") as err:
        drive.read_raw(too_many)
    assert isinstance(err.value, LookupError) and err.value.exception_code == 2
    with pytest.raises(DriveAddressError, match=r"Pr 10\.20 \(latest trip code\)"):
        drive.write(pr.TRIP_CODE, 3)  # read-only


def test_other_exception_replies(drive: UnidriveSP, client: InProcessClient) -> None:
    from pymodbus.pdu import ExceptionResponse

    def reply(code: int):  # type: ignore[no-untyped-def]
        return lambda *a, **k: ExceptionResponse(3, code)

    client.read_holding_registers = reply(3)  # type: ignore[method-assign]
    with pytest.raises(DriveValueError, match="exception 3") as err:
        drive.read(pr.STATUS_WORD)
    assert isinstance(err.value, ValueError)
    client.read_holding_registers = reply(6)  # type: ignore[method-assign]
    with pytest.raises(DriveReplyError, match=r"Pr 10\.40 \(status word\).*exception 6"):
        drive.read(pr.STATUS_WORD)


def test_timeouts_are_retried_then_raised(drive: UnidriveSP, client: InProcessClient) -> None:
    client.fail_next = [ModbusIOException("no reply")] * 2
    assert drive.read(pr.TRIP_CODE) == 0  # third attempt answers
    client.fail_next = [ModbusIOException("no reply")] * 3
    with pytest.raises(DriveTimeoutError, match=r"Pr 10\.20.*no reply after 3 attempts") as err:
        drive.read(pr.TRIP_CODE)
    assert isinstance(err.value, TimeoutError)


def test_lost_link_reconnects_or_raises(drive: UnidriveSP, client: InProcessClient) -> None:
    before = client.connects
    client.fail_next = [ConnectionException("reset by peer")]
    assert drive.read(pr.TRIP_CODE) == 0
    assert client.connects == before + 1
    client.fail_next = [ConnectionException("reset by peer")] * 3
    with pytest.raises(DriveConnectionError) as err:
        drive.read(pr.TRIP_CODE)
    assert isinstance(err.value, ConnectionError)
    # A stand killed mid-run: the socket's own reset, as pymodbus lets it through.
    client.fail_next = [ConnectionResetError(104, "Connection reset by peer")] * 3
    with pytest.raises(DriveConnectionError, match="reset by peer"):
        drive.read(pr.TRIP_CODE)


def test_close_disables_and_refuses_work(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    assert sim.enabled
    with drive:
        pass
    assert drive.closed and not sim.enabled
    with pytest.raises(DriveClosedError, match="closed"):
        drive.poll()
    with pytest.raises(ClosedError):
        drive.enable()
    drive.close()  # idempotent


def test_stand_down_leaves_the_drive_disabled_and_healthy(
    drive: UnidriveSP, sim: SimulatedDrive
) -> None:
    drive.enable()
    run_for(sim, drive, 1.0)
    drive.stand_down()
    sim.advance(round(3 * RATE))  # no polls: a watchdog left armed would trip at 1 s
    state = drive.poll()
    assert state.healthy and not state.active and not state.tripped
    assert sim.params[pr.CONTROL_WORD_ENABLE] == 0
    drive.stand_down()  # idempotent
    drive.enable()  # the next run enables and arms again
    run_for(sim, drive, 1.0)
    assert drive.poll().active
    sim.advance(round(1.5 * RATE))
    assert drive.poll().trip_code == TripCode.WATCHDOG


def test_close_stands_the_watchdog_down(drive: UnidriveSP, sim: SimulatedDrive) -> None:
    drive.enable()
    run_for(sim, drive, 0.5)
    drive.close()
    sim.advance(round(3 * RATE))
    assert sim.trip_code == 0 and not sim.enabled


def test_exception_tree() -> None:
    for cls, builtin in (
        (DriveTimeoutError, TimeoutError),
        (DriveConnectionError, ConnectionError),
        (DriveAddressError, LookupError),
        (DriveValueError, ValueError),
        (DriveProfileError, ValueError),
        (DriveClosedError, RuntimeError),
    ):
        assert issubclass(cls, DriveError) and issubclass(cls, builtin)


def test_urls() -> None:
    with pytest.raises(ValueError, match="tcp:// or rtu://"):
        open_unidrive("udp://127.0.0.1:502", LIMITS)
    with pytest.raises(DriveConnectionError, match="cannot connect"):
        open_unidrive("tcp://127.0.0.1:1", LIMITS, timeout_s=0.2)
    with pytest.raises(DriveConnectionError, match="cannot connect"):
        open_unidrive("rtu:///nonexistent/ttyUSB9", LIMITS)
