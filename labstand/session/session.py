"""The acquisition session: pre-flight, homing, the run, and a safe stop on every path.

The session receives ready-built drivers, a ``DriveInterface`` and a ``GaugeSource``
(``labstand.session.devices`` builds them for the stand or the simulated stand); it never
knows which. Threads:

* the gauge source's reader thread parses the serial port and queues blocks
  (drivers.gauge_stream); it never waits on anybody;
* the session's loop (``labstand.session.loop``), in the caller's thread, takes every
  queued block, checks it, stamps it and hands it on, and polls the drive at
  ``poll_hz`` (each poll toggles the drive's watchdog, so a dead labstand trips it);
* the ``RecordingPipe``'s writer thread does all the disk I/O.

Every way out of ``run`` disables the drive: the normal end, Ctrl-C (first: controlled
stop; second: immediate disable, counted by ``StopRequest`` from a signal handler), and
any ``EStopError``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from drivers.errors import DriveError, GaugeError
from drivers.interfaces import DriveState, GaugeStats
from drivers.signals import DriveProfile, SignalSpec
from drivers.unidrive_profile import ProfileState
from labstand.session.loop import SessionLoop
from labstand.session.record import RecordingPipe
from labstand.session.safety import EStopError, SafetyMonitor

log = logging.getLogger(__name__)

__all__ = ["Outcome", "Preflight", "PreflightError", "RunResult", "Session", "StopRequest"]

T = TypeVar("T")

#: A profile starts only this close to x = 0 (the drive program's tolerance is 0.5 mm).
HOME_TOLERANCE_M = 0.0004
#: A controlled stop must bring the drive to rest within this time, s.
STOP_TIMEOUT_S = 3.0
#: Recording goes on this long after the drive is disabled (the coast-down), s.
TAIL_S = 0.3
#: How long the gauges may take to deliver their first block, s.
FIRST_BLOCK_TIMEOUT_S = 2.0


class PreflightError(Exception):
    """Pre-flight found a device silent (``refused`` False) or not ready (True)."""

    def __init__(self, message: str, refused: bool) -> None:
        super().__init__(message)
        self.refused = refused


class Outcome(StrEnum):
    """How a run ended."""

    DONE = "done"  # the profile ran to its end
    STOPPED = "stopped"  # Ctrl-C (controlled, or twice: immediate disable)
    ESTOP = "estop"  # an emergency stop


class StopRequest:
    """Stop requests (Ctrl-C, SIGTERM), counted by a signal handler and read by the loop.

    ``by`` names the first one as it came ("Ctrl-C" or "SIGTERM"), for the messages.
    """

    def __init__(self) -> None:
        self.presses = 0
        self.by = "Ctrl-C"

    def press(self, by: str = "Ctrl-C") -> None:
        """One more request (safe to call from a signal handler)."""
        if not self.presses:
            self.by = by
        self.presses += 1


@dataclass(frozen=True)
class Preflight:
    """What pre-flight found: the motion to run, the drive and the gauges at rest."""

    profile: DriveProfile
    state: DriveState
    needs_home: bool
    force_n: float  # fibre force at rest, N
    u_mm: float  # weight position at rest, mm


@dataclass(frozen=True)
class RunResult:
    """How the run went."""

    outcome: Outcome
    reason: str
    elapsed_s: float
    samples: int
    stats: GaugeStats
    drive_disabled: bool
    disable_error: str


class Session(SessionLoop):
    """One run on ready-built devices: ``preflight``, ``prepare``, ``run``.

    Parameters are those of ``SessionLoop``.
    """

    # ---- pre-flight ----------------------------------------------------------------
    def preflight(self, spec: SignalSpec, reset_trip: bool = False) -> Preflight:
        """Check devices, drive health and the profile; nothing moves.

        Raises
        ------
        LimitError
            The profile breaks labstand's limits (or labstand's exceed the drive's).
        PreflightError
            A device does not answer (``refused`` False) or the drive is not ready.
        """
        state = self._ask(self.drive.poll, "does not answer")
        if state.tripped and reset_trip:
            log.info("resetting trip %d", state.trip_code)
            self._ask(self.drive.reset_trip, "refused the trip reset")
            state = self._ask(self.drive.poll, "does not answer")
        if state.tripped:
            raise PreflightError(
                f"{self.drive.name} is tripped: {state.trip_description}; find the cause, then "
                "run again with --reset-trip",
                refused=True,
            )
        if not state.healthy:
            raise PreflightError(
                f"{self.drive.name} is not healthy (status word {state.status_word:#06x})",
                refused=True,
            )
        first = self._first_block()
        self._ask(self.drive.check_limits, "cannot report its limits")
        try:
            profile = self.drive.load_profile(spec)
        except DriveError as err:
            raise PreflightError(f"the drive refused the profile: {err}", refused=True) from err
        self.profile = profile
        self.monitor = SafetyMonitor(
            self.safety, spec.amplitude_m * 1e3, self.drive.limits.speed_max_m_s
        )
        needs_home = abs(state.position_m) > HOME_TOLERANCE_M
        if needs_home:
            self.monitor.widen_for(state.position_m * 1e3)
        self.state = state
        return Preflight(
            profile,
            state,
            needs_home,
            float(np.median(first["force_n"])),
            float(np.median(first["u_mm"])),
        )

    def _ask(self, call: Callable[[], T], what: str) -> T:
        try:
            return call()
        except DriveError as err:
            raise PreflightError(f"{self.drive.name} {what}: {err}", refused=False) from err

    def _first_block(self) -> NDArray[np.void]:
        deadline = time.monotonic() + FIRST_BLOCK_TIMEOUT_S
        while time.monotonic() < deadline:
            try:
                block = self.gauges.read_block(0.1)
            except GaugeError as err:
                raise PreflightError(f"{self.gauges.name}: {err}", refused=False) from err
            if block is not None and len(block):
                self.clock.observe(block)
                self._last_data_s = time.monotonic()
                return block
        raise PreflightError(
            f"{self.gauges.name} sent no data within {FIRST_BLOCK_TIMEOUT_S:g} s", refused=False
        )

    # ---- prepare: enable and home ----------------------------------------------------
    def prepare(self, pre: Preflight, stop: StopRequest) -> None:
        """Enable the drive and, if it stands away from x = 0, home it (not recorded).

        Raises
        ------
        EStopError
            A safety rule fired or Ctrl-C was pressed; the drive is disabled.
        """
        self._drain()
        try:
            self.settle()
            self.drive.enable()
            self._wait_active()
            if pre.needs_home:
                self.phase = "homing"
                self.settle()
                self.drive.home()
                self._until_done(stop, "homing")
                self.settle()
                self.profile = self.drive.load_profile(pre.profile.spec)
        except (EStopError, DriveError) as err:
            self.disable()
            raise EStopError(str(err)) from err

    def _until_done(self, stop: StopRequest, what: str) -> None:
        self.state = None
        while True:
            self._pass(expect_active=True)
            if stop.presses:
                raise EStopError(f"{stop.by} while {what}")
            if self._polled and self.state is not None:
                if self.state.profile_state is ProfileState.DONE:
                    return
                if self.state.profile_state is not ProfileState.RUNNING:
                    name = self.state.profile_state.name.lower()
                    raise EStopError(f"the drive program stopped while {what} (state {name})")

    # ---- the run ---------------------------------------------------------------------
    def run(self, pipe: RecordingPipe, stop: StopRequest, title: str) -> RunResult:
        """Run the loaded profile, recording into ``pipe``; the drive ends disabled."""
        if self.profile is None:
            raise RuntimeError("run() before preflight()")
        self.pipe = pipe
        self._drain()
        self._seen = self.gauges.stats()
        outcome, reason = Outcome.ESTOP, ""
        try:
            while pipe.samples == 0:  # the first recorded sample is t = 0
                self._pass(expect_active=True)
            outcome, reason = self._run_profile(stop, title)
        except (EStopError, DriveError) as err:
            reason = str(err)
            log.info("e-stop: %s", reason)
            self._event("estop", reason)  # the moment the rule fired, before the disable
            self.disable()
        else:
            self.disable()
        self._tail()
        if outcome is Outcome.STOPPED and stop.presses >= 2 and "immediate" not in reason:
            # the second press came once the controlled stop was done: what the terminal
            # said ("disabling the drive at once") is what the recording and the end say
            outcome, reason = self._immediate(stop, after=reason)
        self._show(force=True)
        return RunResult(
            outcome,
            reason,
            self._elapsed(),
            pipe.samples,
            self.gauges.stats(),
            self.drive_disabled,
            self.disable_error,
        )

    def _run_profile(self, stop: StopRequest, title: str) -> tuple[Outcome, str]:
        self.settle()
        t_a = time.monotonic()
        self.drive.start()
        self._start_s = (t_a + time.monotonic()) / 2
        self.clock.profile_start_us = self.clock.host_to_device_us(self._start_s)
        self._event("start", title)
        self.phase, self.monitor.running, self.state = "running", True, None
        while True:
            self._pass(expect_active=True)
            if stop.presses >= 2:
                return self._immediate(stop)
            if stop.presses:
                return self._controlled_stop(stop)
            if self.pipe is not None and self.pipe.error is not None:
                raise EStopError(f"writing {self.pipe.path} failed: {self.pipe.error}")
            if self._polled and self.state is not None:
                state = self.state.profile_state
                if state is ProfileState.DONE:
                    self._event("stop", "profile done")
                    return Outcome.DONE, "profile done"
                if state is not ProfileState.RUNNING:
                    name = state.name.lower()
                    raise EStopError(f"the drive program stopped the profile (state {name})")

    def _immediate(self, stop: StopRequest, after: str = "") -> tuple[Outcome, str]:
        self.disable()
        reason = f"{stop.by} twice at {self._elapsed():.2f} s: immediate disable"
        if after:
            reason = f"{after}, then {reason}"
        self._event("estop", reason)
        return Outcome.STOPPED, reason

    def _controlled_stop(self, stop: StopRequest) -> tuple[Outcome, str]:
        reason = f"{stop.by} at {self._elapsed():.2f} s: controlled stop"
        self.phase, self.monitor.running = "stopping", False
        self.settle()
        self.drive.stop()
        self._event("stop", reason)
        deadline = time.monotonic() + STOP_TIMEOUT_S
        while True:
            self._pass(expect_active=True)
            if stop.presses >= 2:
                return self._immediate(stop)
            st = self.state
            if (
                self._polled
                and st is not None
                and st.profile_state is not ProfileState.RUNNING
                and abs(st.velocity_m_s) < 1e-3
            ):
                return Outcome.STOPPED, reason
            if time.monotonic() > deadline:
                raise EStopError(f"the drive did not come to rest within {STOP_TIMEOUT_S:g} s")

    def _tail(self) -> None:
        """Record the coast-down for TAIL_S (polls show the drive disabled); best effort."""
        self.phase, self.monitor.running, self._checking = "stopped", False, False
        end = time.monotonic() + TAIL_S
        while time.monotonic() < end:
            try:
                self._pass(expect_active=False)
            except EStopError as err:  # a device that failed: nothing more to record from it
                log.info("after the stop: %s", err)
                break
