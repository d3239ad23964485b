"""The simulated drive as a state machine: registers, servo, trips, profile program."""

from __future__ import annotations

import numpy as np
import pytest
from pymodbus.constants import ExcCodes

from drivers import unidrive_registers as pr
from drivers.limits import DriveLimits
from drivers.signals import Shape, SignalSpec, plan_motion
from drivers.unidrive_profile import ProfileState, RejectReason, encode_home, encode_profile
from drivers.unidrive_registers import ControlBit, StatusBit, TripCode
from sim.hardware.drive import SimulatedDrive
from sim.hardware.modbus_server import read_request, write_request

RATE = 2000.0
LIMITS = DriveLimits()
AUTO, ENABLE, RUN = ControlBit.AUTO.mask, ControlBit.ENABLE.mask, ControlBit.RUN_FWD.mask
WD = ControlBit.WATCHDOG.mask


def write(d: SimulatedDrive, reg: pr.Register, *raws: int) -> None:
    words: list[int] = []
    for raw in raws:
        words += [(raw >> 16) & 0xFFFF, raw & 0xFFFF] if reg.width == 32 else [raw & 0xFFFF]
    assert write_request(d, reg.address, words) is None


def read(d: SimulatedDrive, reg: pr.Register) -> int:
    words = read_request(d, reg.address, reg.count)
    assert isinstance(words, list)
    value = (words[0] << 16 | words[1]) if reg.width == 32 else words[0]
    bits = reg.width
    return value - (1 << bits) if value >> (bits - 1) else value


def enabled_drive() -> SimulatedDrive:
    d = SimulatedDrive(LIMITS, RATE)
    write(d, pr.CONTROL_WORD_ENABLE, 1)
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)
    return d


def run_profile(spec: SignalSpec) -> tuple[SimulatedDrive, np.ndarray, np.ndarray]:
    d = enabled_drive()
    write(d, pr.PROFILE_SHAPE, *encode_profile(spec))
    assert read(d, pr.PROFILE_STATE) == ProfileState.ARMED
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | RUN)
    t0 = d.t_s
    profile = plan_motion(spec, LIMITS)
    n = round((profile.duration_s + 0.05) * RATE)
    x = d.advance(n)
    t = t0 + np.arange(1, n + 1) / RATE
    return d, t - t0, x


# ---- registers ---------------------------------------------------------------------
def test_register_limits_and_unknown_parameters() -> None:
    d = SimulatedDrive(LIMITS, RATE)
    assert isinstance(read_request(d, pr.STATUS_BLOCK[0].address, 16), list)
    assert read_request(d, pr.STATUS_BLOCK[0].address, 18) == ExcCodes.ILLEGAL_ADDRESS
    assert read_request(d, 5 * 100, 1) == ExcCodes.ILLEGAL_ADDRESS  # Pr 5.01: unknown
    assert read_request(d, pr.TRIP_CODE.address, 2) == ExcCodes.ILLEGAL_ADDRESS  # 10.21 unknown
    assert read_request(d, pr.SPEED_REFERENCE.address, 1) == ExcCodes.ILLEGAL_ADDRESS  # odd
    assert write_request(d, pr.TRIP_CODE.address, [1]) == ExcCodes.ILLEGAL_ADDRESS  # read-only
    assert write_request(d, pr.CONTROL_WORD.address, [0] * 17) == ExcCodes.ILLEGAL_ADDRESS


def test_32bit_values_are_high_word_first_and_16bit_reads_get_the_low_word() -> None:
    d = SimulatedDrive(LIMITS, RATE)
    raw = -123456  # 0.1 rpm
    assert (
        write_request(d, pr.SPEED_REFERENCE.address, [(raw >> 16) & 0xFFFF, raw & 0xFFFF]) is None
    )
    assert read_request(d, pr.SPEED_REFERENCE.address, 2) == [0xFFFE, 0x1DC0]
    assert read_request(d, pr.SPEED_REFERENCE.address16, 1) == [0x1DC0]


# ---- motion ------------------------------------------------------------------------
@pytest.mark.parametrize(
    "spec",
    [
        SignalSpec(Shape.RECTANGULAR, 0.05, 1.0, 2, dwell_start_s=0.1, dwell_end_s=0.2),
        SignalSpec(Shape.TRAPEZOIDAL, 0.04, 1.5, 2, 0.2, 0.1, 0.2),
        SignalSpec(Shape.QUASI_SINUSOIDAL, 0.05, 2.0, 2, dwell_start_s=0.1, dwell_end_s=0.2),
    ],
    ids=lambda s: str(s.shape),
)
def test_servo_follows_the_planned_motion_with_a_small_lag(spec: SignalSpec) -> None:
    d, t, x = run_profile(spec)
    profile = plan_motion(spec, LIMITS)
    lag = d.settings.reference_delay_s
    lagged = profile.position_m(t - lag)
    assert np.max(np.abs(x - lagged)) < 0.1e-3  # within 0.1 mm of r(t − lag)
    err_now = np.max(np.abs(x - profile.position_m(t)))
    assert err_now <= profile.peak_speed_m_s * lag * 1.1 + 0.1e-3  # lag × speed, no more
    assert np.max(np.abs(np.diff(x))) * RATE <= LIMITS.speed_max_m_s * d.settings.speed_margin
    assert x.max() == pytest.approx(spec.amplitude_m, abs=0.1e-3)
    assert read(d, pr.PROFILE_STATE) == ProfileState.DONE
    assert abs(x[-1]) < 1e-5


def test_speed_mode_runs_into_the_over_travel_trip() -> None:
    d = enabled_drive()
    rpm = 3000.0  # 0.5 m/s with a 10 mm lead
    write(d, pr.SPEED_REFERENCE, pr.SPEED_REFERENCE.to_raw(rpm))
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | RUN | ControlBit.REMOTE.mask)
    x = d.advance(round(0.5 * RATE))
    assert d.trip_code == TripCode.OVER_TRAVEL
    limit = LIMITS.amplitude_max_m + d.settings.over_travel_margin_m
    k = int(np.argmax(x > limit))
    assert k > 0 and d.trips[0][0] == pytest.approx((k + 1) / RATE)
    assert read(d, pr.STATUS_WORD) & StatusBit.ACTIVE.mask == 0
    accel = np.diff(x, 2) * RATE**2
    assert np.max(np.abs(accel)) <= LIMITS.accel_max_m_s2 * d.settings.accel_margin * 1.01
    assert d.servo.v_m_s == 0.0  # braked to a stop after the trip


def test_watchdog_is_armed_by_its_first_edge_and_trips_after_one_second() -> None:
    d = enabled_drive()
    d.advance(round(3 * RATE))
    assert d.trip_code == 0  # not armed yet: no edge of bit 14 so far
    word = AUTO | ENABLE
    for _ in range(10):  # toggling every 0.2 s: edges every 0.4 s
        word ^= WD
        write(d, pr.CONTROL_WORD, word)
        d.advance(round(0.2 * RATE))
    assert d.trip_code == 0
    last_edge = d._wd_last_edge_s
    d.advance(round(1.5 * RATE))
    assert d.trip_code == TripCode.WATCHDOG
    assert d.trips[-1][0] == pytest.approx(last_edge + 1.0, abs=1.5 / RATE)


def armed_and_toggled() -> SimulatedDrive:
    d = enabled_drive()
    for word in (AUTO | ENABLE | WD, AUTO | ENABLE):  # the first 0 → 1 edge arms it
        write(d, pr.CONTROL_WORD, word)
        d.advance(round(0.2 * RATE))
    return d


@pytest.mark.parametrize("how", ["Pr 6.43 = 0", "AUTO cleared"])
def test_watchdog_stands_down_with_the_control_word(how: str) -> None:
    # HARDWARE.md: the control word (bit 14 included) acts only with Pr 6.43 = 1 and AUTO
    d = armed_and_toggled()
    write(d, pr.CONTROL_WORD, AUTO)  # disabled first, as labstand does
    if how == "AUTO cleared":
        write(d, pr.CONTROL_WORD, 0)
    else:
        write(d, pr.CONTROL_WORD_ENABLE, 0)
    d.advance(round(5 * RATE))
    assert d.trip_code == 0 and not d.enabled
    assert read(d, pr.STATUS_WORD) & StatusBit.HEALTHY.mask
    # toggling bit 14 while the word is inactive arms nothing
    write(d, pr.CONTROL_WORD, WD)
    d.advance(round(2 * RATE))
    assert d.trip_code == 0


def test_watchdog_re_arms_at_the_next_edge_after_a_stand_down() -> None:
    d = armed_and_toggled()
    write(d, pr.CONTROL_WORD, AUTO)
    write(d, pr.CONTROL_WORD_ENABLE, 0)
    d.advance(round(3 * RATE))
    write(d, pr.CONTROL_WORD_ENABLE, 1)
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)
    d.advance(round(1.5 * RATE))
    assert d.trip_code == 0  # not armed again until its edge (no stale deadline)
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | WD)
    d.advance(round(1.5 * RATE))
    assert d.trip_code == TripCode.WATCHDOG  # and then a dead controller trips it again


def test_controller_that_stops_with_the_word_active_trips() -> None:
    d = armed_and_toggled()
    write(d, pr.CONTROL_WORD, AUTO)  # disabled, but the word (and its watchdog) in force
    d.advance(round(1.5 * RATE))
    assert d.trip_code == TripCode.WATCHDOG


def test_user_trip_reset_and_enable_edge() -> None:
    d = enabled_drive()
    write(d, pr.USER_TRIP, 45)
    assert (read(d, pr.TRIP_CODE), read(d, pr.DRIVE_HEALTHY)) == (45, 0)
    assert read(d, pr.USER_TRIP) == 0
    write(d, pr.USER_TRIP, 100)
    assert read(d, pr.TRIP_CODE) == 0 and read(d, pr.STATUS_WORD) & StatusBit.HEALTHY.mask
    assert not d.enabled  # the ENABLE bit is still set, but a new edge is needed
    write(d, pr.CONTROL_WORD, AUTO)
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)
    assert d.enabled


def test_control_word_trip_and_reset_bits() -> None:
    d = enabled_drive()
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | ControlBit.TRIP.mask)
    assert d.trip_code == TripCode.CONTROL_WORD
    write(d, pr.CONTROL_WORD, AUTO | ControlBit.RESET.mask)
    assert d.trip_code == 0


def test_control_word_is_ignored_without_pr_6_43_and_auto() -> None:
    d = SimulatedDrive(LIMITS, RATE)
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)
    assert not d.enabled  # Pr 6.43 = 0
    write(d, pr.CONTROL_WORD_ENABLE, 1)
    write(d, pr.CONTROL_WORD, ENABLE)
    assert not d.enabled  # AUTO clear
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)
    assert d.enabled and read(d, pr.STATUS_WORD) & StatusBit.ACTIVE.mask


def test_profile_rejections() -> None:
    d = enabled_drive()
    too_fast = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.08, 3.0, 1)
    write(d, pr.PROFILE_SHAPE, *encode_profile(too_fast))
    assert (read(d, pr.PROFILE_STATE), read(d, pr.REJECT_REASON)) == (
        ProfileState.REJECTED,
        RejectReason.LIMITS,
    )
    write(d, pr.PROFILE_SHAPE, 9)
    assert read(d, pr.REJECT_REASON) == RejectReason.BAD_SHAPE
    bad = encode_profile(SignalSpec(Shape.TRAPEZOIDAL, 0.01, 1.0, 1))
    bad[3] = 0  # zero cycles
    write(d, pr.PROFILE_SHAPE, *bad)
    assert read(d, pr.REJECT_REASON) == RejectReason.BAD_VALUE
    ok = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.02, 1.0, 1, dwell_start_s=0.0)
    write(d, pr.PROFILE_SHAPE, *encode_profile(ok))
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | RUN)
    d.advance(round(0.3 * RATE))
    write(d, pr.PROFILE_SHAPE, *encode_profile(ok))
    assert read(d, pr.PROFILE_STATE) == ProfileState.RUNNING
    assert read(d, pr.REJECT_REASON) == RejectReason.BUSY
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)  # controlled stop, away from home
    d.advance(round(0.3 * RATE))
    assert read(d, pr.PROFILE_STATE) == ProfileState.ABORTED
    write(d, pr.PROFILE_SHAPE, *encode_profile(ok))
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | RUN)
    assert read(d, pr.REJECT_REASON) == RejectReason.NOT_AT_HOME
    write(d, pr.CONTROL_WORD, AUTO | ENABLE)
    write(d, pr.PROFILE_SHAPE, *encode_home())
    write(d, pr.CONTROL_WORD, AUTO | ENABLE | RUN)
    x = d.advance(round(0.5 * RATE))
    assert abs(x[-1]) < 1e-6 and read(d, pr.PROFILE_STATE) == ProfileState.DONE
    assert np.max(np.abs(np.diff(x))) * RATE <= LIMITS.speed_max_m_s * 1.01
