"""The simulated Unidrive SP: parameters, control word, trips and labstand's drive program.

A pure state machine with no I/O and no clock of its own: the stand advances it sample by
sample (``advance``), and the Modbus server hands it register reads and writes between
steps. It implements the same parameter table as the driver
(``drivers.unidrive_registers``) and the behaviour HARDWARE.md describes:

* at most 16 registers per request, exception 2 beyond; exception 2 for parameters the
  table does not know, for writes to read-only ones, and for odd 32-bit counts;
* 32-bit access (bit 14 of the address): two registers per parameter, high word first;
  a 16-bit read of a 32-bit parameter returns the low word only;
* the control word (active when Pr 6.43 = 1 and AUTO is set): ENABLE, RUN FWD / RUN REV /
  RUN with FWD/REV, REMOTE (speed mode from Pr 1.21), TRIP, RESET and the watchdog
  (armed by the first 0 → 1 edge of bit 14 while the word is active; trip 30 when the
  next edge is more than 1 s late). The watchdog is a bit of the control word, so it
  stands down with it: clearing Pr 6.43 (or AUTO) disarms it, and it re-arms only at a
  new 0 → 1 edge once the word is active again. A controller that died leaves the word
  active and the watchdog armed, so the drive trips;
* trips: watchdog (30), over-travel (41: |x| beyond the amplitude limit + margin),
  control-word trip (52), user trips 40–89 written to Pr 10.38; writing 100 resets. A
  trip disables the output; after a reset the drive waits for a new ENABLE edge;
* the drive-resident profile of docs/hardware-design.md (Pr 20.21–20.39).
"""

from __future__ import annotations

import logging
import math

import numpy as np
from numpy.typing import NDArray

from drivers import unidrive_registers as pr
from drivers.limits import DriveLimits, InvalidSignalError, LimitError
from drivers.signals import plan_motion
from drivers.unidrive_profile import ProfileState, RejectReason, ShapeCode, decode_profile
from drivers.unidrive_registers import ControlBit, Register, StatusBit, TripCode
from sim.hardware.servo import Motion, PointToPoint, ServoSettings, ServoState

log = logging.getLogger(__name__)

__all__ = ["ILLEGAL_ADDRESS", "SimulatedDrive"]

ILLEGAL_ADDRESS = 2  # Modbus exception code
_RW_DEFAULTS = {
    pr.DRIVE_ENABLE: 1,
    pr.SERIAL_ADDRESS: 1,
    pr.SERIAL_MODE: 1,
    pr.SERIAL_BAUD: 9,  # 115200 [manual]
    pr.SERIAL_DELAY: 2,  # ms [manual]
}


class SimulatedDrive:
    """The drive converter and its position servo.

    Parameters
    ----------
    limits
        The limits commissioned on the drive (profiles are planned against them).
    rate_hz
        Sample rate at which ``advance`` returns positions, Hz.
    settings
        Servo, trip and mechanics settings.
    """

    def __init__(
        self, limits: DriveLimits, rate_hz: float, settings: ServoSettings | None = None
    ) -> None:
        self.limits = limits
        self.rate_hz = rate_hz
        self.settings = settings or ServoSettings()
        s = self.settings
        w = 2 * math.pi * s.bandwidth_hz
        self._gains = (w * w, 2 * w)
        self._v_hw = limits.speed_max_m_s * s.speed_margin
        self._a_hw = limits.accel_max_m_s2 * s.accel_margin
        self.k = 0  # samples advanced; the drive's time is k / rate_hz
        self.servo = ServoState()
        self.params: dict[Register, int] = {r: 0 for r in pr.REGISTERS if r.access is pr.Access.RW}
        self.params.update(_RW_DEFAULTS)
        self.trip_code = 0
        self.trips: list[tuple[float, int]] = []  # (time s, code), for tests and logs
        self._latched_off = False  # after a trip: wait for a new ENABLE edge
        self._wd_armed = False
        self._wd_last_edge_s = 0.0
        self.profile_state = ProfileState.IDLE
        self.reject_reason = RejectReason.NONE
        self._motion: Motion | None = None  # armed or running
        self._home_armed = False
        self._t0 = 0.0  # profile start
        self._mode = "off"  # off | motion | velocity
        self._ref = (0.0, 0.0, 0.0)  # r, ṙ, r̈ last used
        self._vel_target = 0.0

    # ---- time and motion -------------------------------------------------------------
    @property
    def t_s(self) -> float:
        """The drive's time, s."""
        return self.k / self.rate_hz

    @property
    def enabled(self) -> bool:
        """The output is enabled (control word active, ENABLE set, not tripped)."""
        cw = self.params[pr.CONTROL_WORD]
        return (
            self.params[pr.CONTROL_WORD_ENABLE] == 1
            and bool(cw & ControlBit.AUTO.mask)
            and bool(cw & ControlBit.ENABLE.mask)
            and self.params[pr.DRIVE_ENABLE] != 0
            and self.trip_code == 0
            and not self._latched_off
        )

    def advance(self, n: int) -> NDArray[np.float64]:
        """Run the drive over the next n samples; returns x at each, m."""
        s = self.settings
        sub = s.substeps
        dt = 1.0 / (self.rate_hz * sub)
        ticks = self.k * sub + np.arange(1, n * sub + 1)
        t_sub = ticks / (self.rate_hz * sub)
        planned = None
        if self._mode == "motion" and self._motion is not None:
            tau = t_sub - self._t0 - s.reference_delay_s
            m = self._motion
            planned = (m.position_m(tau), m.velocity_m_s(tau), m.accel_m_s2(tau))
        out = np.empty(n)
        for i in range(n):
            for j in range(sub):
                idx = i * sub + j
                if self._mode == "off":
                    self.servo.coast(dt, self._a_hw)
                    self._ref = (self.servo.x_m, self.servo.v_m_s, 0.0)
                    continue
                if self._mode == "motion" and planned is not None:
                    self._ref = (
                        float(planned[0][idx]),
                        float(planned[1][idx]),
                        float(planned[2][idx]),
                    )
                else:
                    self._velocity_ref(dt)
                self.servo.step(dt, self._ref, self._gains, self._v_hw, self._a_hw)
            self.k += 1
            out[i] = self.servo.x_m
            self._checks()
        return out

    def _velocity_ref(self, dt: float) -> None:
        r, rv, _ = self._ref
        a = self.limits.accel_max_m_s2
        dv = min(max(self._vel_target - rv, -a * dt), a * dt)
        self._ref = (r + (rv + dv) * dt, rv + dv, dv / dt)

    def _checks(self) -> None:
        t, s = self.t_s, self.settings
        if self._wd_armed and t - self._wd_last_edge_s > s.watchdog_timeout_s:
            self.trip(TripCode.WATCHDOG)
        over = abs(self.servo.x_m) > self.limits.amplitude_max_m + s.over_travel_margin_m
        if over and self.trip_code == 0:
            self.trip(TripCode.OVER_TRAVEL)
        motion = self._motion
        if (
            self.profile_state is ProfileState.RUNNING
            and motion is not None
            and t - self._t0 >= motion.duration_s + s.reference_delay_s
        ):
            self.profile_state = ProfileState.DONE
            self._hold()

    def _hold(self) -> None:
        """Hold where the reference is (velocity mode with target 0)."""
        self._mode = "velocity"
        self._vel_target = 0.0
        self._ref = (self._ref[0], self._ref[1], 0.0)

    # ---- trips -----------------------------------------------------------------------
    def trip(self, code: int) -> None:
        """Trip the drive: output off at once, profile aborted, watchdog disarmed."""
        if self.trip_code:
            return
        log.info("simulated drive trips at %.3f s: trip %d", self.t_s, code)
        self.trip_code = int(code)
        self.trips.append((self.t_s, int(code)))
        self._latched_off = True
        self._wd_armed = False
        self._output_off()

    def reset(self) -> None:
        """Clear a trip; the drive stays disabled until ENABLE rises again."""
        if self.trip_code:
            log.info("simulated drive reset at %.3f s (was trip %d)", self.t_s, self.trip_code)
        self.trip_code = 0
        self._wd_armed = False

    def _word_inactive(self) -> None:
        """The control word stopped counting (Pr 6.43 or AUTO cleared): off, watchdog down."""
        if self._wd_armed:
            log.info("simulated drive: control word inactive at %.3f s, watchdog down", self.t_s)
        self._wd_armed = False
        self._output_off()

    def _output_off(self) -> None:
        if self.profile_state is ProfileState.RUNNING:
            self.profile_state = ProfileState.ABORTED
        self._mode = "off"

    # ---- the control word ------------------------------------------------------------
    def _control_word(self, old: int, new: int) -> None:
        rise, fall = new & ~old, old & ~new
        active = self.params[pr.CONTROL_WORD_ENABLE] == 1 and bool(new & ControlBit.AUTO.mask)
        if not active:
            self._word_inactive()
            return
        if rise & ControlBit.WATCHDOG.mask:
            self._wd_armed, self._wd_last_edge_s = True, self.t_s
        if rise & ControlBit.TRIP.mask:
            self.trip(TripCode.CONTROL_WORD)
        if rise & ControlBit.RESET.mask:
            self.reset()
        if rise & ControlBit.ENABLE.mask and self.trip_code == 0:
            self._latched_off = False
        was_on = self._mode != "off"
        if not self.enabled:
            self._output_off()
            return
        if not was_on:  # just enabled: hold where the axis stands
            self._ref = (self.servo.x_m, 0.0, 0.0)
            self._hold()
        if new & ControlBit.REMOTE.mask:
            self._speed_mode(new)
        elif fall & ControlBit.REMOTE.mask:
            self._hold()
        elif rise & ControlBit.RUN_FWD.mask:
            self._start_profile()
        elif fall & ControlBit.RUN_FWD.mask and self.profile_state is ProfileState.RUNNING:
            self.profile_state = ProfileState.ABORTED  # controlled stop at the limits
            self._ref = (self.servo.x_m, self.servo.v_m_s, 0.0)
            self._hold()

    def _speed_mode(self, cw: int) -> None:
        run = cw & (ControlBit.RUN_FWD.mask | ControlBit.RUN_REV.mask | ControlBit.RUN.mask)
        reverse = bool(cw & ControlBit.RUN_REV.mask) or (
            bool(cw & ControlBit.RUN.mask) and bool(cw & ControlBit.FWD_REV.mask)
        )
        rpm = pr.SPEED_REFERENCE.to_value(self.params[pr.SPEED_REFERENCE])
        speed = rpm / 60.0 * self.settings.lead_m_per_rev
        if self._mode == "motion":
            self.profile_state = ProfileState.ABORTED
            self._ref = (self.servo.x_m, self.servo.v_m_s, 0.0)
        self._mode = "velocity"
        target = (-speed if reverse else speed) if run else 0.0
        self._vel_target = min(max(target, -self._v_hw), self._v_hw)

    def _start_profile(self) -> None:
        if self.profile_state is not ProfileState.ARMED or self._motion is None:
            return
        if self._home_armed:
            self._motion = PointToPoint(self.servo.x_m, 0.0, self.limits)
        elif abs(self.servo.x_m) > self.settings.home_tolerance_m:
            self._reject(RejectReason.NOT_AT_HOME)
            return
        self._t0 = self.t_s
        self.profile_state = ProfileState.RUNNING
        self._mode = "motion"
        log.info("simulated drive starts a profile at %.3f s", self._t0)

    # ---- the drive program's profile block -------------------------------------------
    def _reject(self, reason: RejectReason) -> None:
        self.profile_state, self.reject_reason = ProfileState.REJECTED, reason
        self._motion = None

    def arm_profile(self) -> None:
        """The drive program reads Pr 20.21–20.27 (after a write to any of them)."""
        if self.profile_state is ProfileState.RUNNING:
            self.reject_reason = RejectReason.BUSY
            return
        raws = [self.params[r] for r in pr.PROFILE_BLOCK]
        self._home_armed = False
        self.reject_reason = RejectReason.NONE
        if raws[0] == ShapeCode.NONE:
            self.profile_state, self._motion = ProfileState.IDLE, None
            return
        if raws[0] == ShapeCode.HOME:
            self._home_armed = True
            self._motion = PointToPoint(0.0, 0.0, self.limits)  # replaced at start
            self.profile_state = ProfileState.ARMED
            return
        try:
            spec = decode_profile(raws)
        except ValueError:
            self._reject(RejectReason.BAD_SHAPE)
            return
        try:
            planned: Motion = plan_motion(spec, self.limits)
        except InvalidSignalError as err:  # no motion at all (0 cycles, NaN, ...)
            log.info("simulated drive refuses a profile: %s", err)
            self._reject(RejectReason.BAD_VALUE)
            return
        except LimitError as err:
            bad = (
                spec.amplitude_m <= 0
                or spec.frequency_hz <= 0
                or spec.cycles < 1
                or min(spec.dwell_start_s, spec.dwell_end_s) < 0
                or not 0 < spec.ramp_fraction <= 0.5
            )
            log.info("simulated drive refuses a profile: %s", err)
            self._reject(RejectReason.BAD_VALUE if bad else RejectReason.LIMITS)
            return
        self._motion = planned
        self.profile_state = ProfileState.ARMED

    # ---- parameter values ------------------------------------------------------------
    def status_word(self) -> int:
        """Pr 10.40 now."""
        v, rd = self.servo.v_m_s, self._ref[1]
        word = 0
        if self.trip_code == 0:
            word |= StatusBit.HEALTHY.mask
        if self._mode != "off":
            word |= StatusBit.ACTIVE.mask
            if abs(v - rd) < 0.01:
                word |= StatusBit.AT_SPEED.mask
        if abs(v) < 0.001:
            word |= StatusBit.ZERO_SPEED.mask
        if rd < -0.001:
            word |= StatusBit.DIRECTION_COMMANDED.mask
        if v < -0.001:
            word |= StatusBit.DIRECTION_RUNNING.mask
        return word

    def value(self, reg: Register) -> int:
        """The raw value a read of ``reg`` returns now."""
        if reg in self.params:
            return 0 if reg is pr.USER_TRIP else self.params[reg]
        x, v, lead = self.servo.x_m, self.servo.v_m_s, self.settings.lead_m_per_rev
        running = self.profile_state in {
            ProfileState.RUNNING,
            ProfileState.DONE,
            ProfileState.ABORTED,
        }
        computed = {
            pr.SPEED_FEEDBACK: pr.SPEED_FEEDBACK.to_raw(v / lead * 60.0),
            pr.ENCODER_TURNS: math.floor(x / lead),
            pr.ENCODER_POSITION: int((x / lead - math.floor(x / lead)) * 65536),
            pr.ENCODER_FINE: 0,
            pr.DRIVE_HEALTHY: int(self.trip_code == 0),
            pr.TRIP_CODE: self.trip_code,
            pr.STATUS_WORD: self.status_word(),
            pr.LIMIT_AMPLITUDE: pr.LIMIT_AMPLITUDE.to_raw(self.limits.amplitude_max_m),
            pr.LIMIT_SPEED: pr.LIMIT_SPEED.to_raw(self.limits.speed_max_m_s),
            pr.LIMIT_ACCEL: pr.LIMIT_ACCEL.to_raw(self.limits.accel_max_m_s2),
            pr.POSITION: pr.POSITION.to_raw(x),
            pr.VELOCITY: pr.VELOCITY.to_raw(v),
            pr.REFERENCE: pr.REFERENCE.to_raw(self._ref[0]),
            pr.PROFILE_TIME: pr.PROFILE_TIME.to_raw(self.t_s - self._t0) if running else 0,
            pr.PROFILE_STATE: int(self.profile_state),
            pr.STATUS_MIRROR: self.status_word(),
            pr.TRIP_MIRROR: self.trip_code,
            pr.DRIVE_CLOCK: round(self.t_s * 1e3) % 2**31,
            pr.REJECT_REASON: int(self.reject_reason),
        }
        return computed[reg]

    def set_value(self, reg: Register, raw: int) -> None:
        """A write of ``raw`` to ``reg`` by a Modbus client (checked by the caller)."""
        if reg is pr.USER_TRIP:
            if raw == pr.USER_TRIP_RESET:
                self.reset()
            elif raw in pr.USER_TRIP_RANGE:
                self.trip(raw)
            return
        old = self.params[reg]
        self.params[reg] = raw
        if reg is pr.CONTROL_WORD:
            self._control_word(old & 0xFFFF, raw & 0xFFFF)
        elif reg is pr.CONTROL_WORD_ENABLE and raw != 1:
            self._word_inactive()
        elif reg in (pr.CONTROL_WORD_ENABLE, pr.DRIVE_ENABLE) and not self.enabled:
            self._output_off()
        elif (
            reg is pr.SPEED_REFERENCE
            and self.params[pr.CONTROL_WORD] & ControlBit.REMOTE.mask
            and self.enabled
        ):
            self._speed_mode(self.params[pr.CONTROL_WORD])
