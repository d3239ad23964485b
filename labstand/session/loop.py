"""The session's device loop: gauge blocks in, drive polls, checks, display, disable.

``SessionLoop`` is the machinery under ``labstand.session.Session``. One ``_pass``
takes every queued gauge block (stamped by the ``RunClock``, handed to the
``RecordingPipe``, checked by the ``SafetyMonitor``), checks the gauge stream's
silence, polls the drive when a poll is due (each poll toggles the drive's watchdog)
and refreshes the display. It never touches the disk.

A drive poll runs on a worker thread and the passes go on while it waits: a drive that
stops answering keeps its driver in time-outs and retries (3 × 0.25 s), and the gauge
rules must be evaluated meanwhile. Every other drive call waits for the poll in flight
first (``settle``), so the drive is only ever used by one thread at a time.
"""

from __future__ import annotations

import contextlib
import logging
import math
import threading
import time
from collections import deque
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from concurrent.futures import wait as wait_for

import numpy as np
from numpy.typing import NDArray

from drivers.errors import ClosedError, DriveError, GaugeError
from drivers.interfaces import DriveInterface, DriveState, GaugeSource, GaugeStats
from drivers.signals import DriveProfile
from labstand.session.display import Display, RunStatus
from labstand.session.record import RecordingPipe, RunClock
from labstand.session.safety import EStopError, SafetyLimits, SafetyMonitor
from recordings.schema import concat_blocks

log = logging.getLogger(__name__)

#: How long a pass waits for a poll it has just sent before going on (a drive that
#: answers does so in a few ms; one that does not is collected by a later pass), s.
PROMPT_ANSWER_S = 0.02
#: An e-stop waits this long for a poll in flight before it gives the drive up as not
#: answering (then its watchdog, not a disable, stops it), s.
STOP_SETTLE_S = 0.1
#: A drive that has not answered a poll for this long is an e-stop, whatever its driver's
#: retries would still try (3 × 0.25 s): two of its time-outs, s (docs/acquisition.md).
DRIVE_ANSWER_S = 0.5

__all__ = ["SessionLoop"]


class SessionLoop:
    """The device loop of a run.

    Parameters
    ----------
    drive, gauges
        The devices; ``shutdown`` closes them.
    safety
        The emergency-stop thresholds.
    display
        Where the live status goes.
    poll_hz
        Drive polls per second (≥ 4: the watchdog needs a toggle within 1 s).
    """

    def __init__(
        self,
        drive: DriveInterface,
        gauges: GaugeSource,
        safety: SafetyLimits | None = None,
        display: Display | None = None,
        poll_hz: float = 20.0,
    ) -> None:
        if not poll_hz >= 4:
            raise ValueError(f"poll rate must be ≥ 4 Hz (the drive's watchdog), got {poll_hz:g}")
        self.drive, self.gauges = drive, gauges
        self.safety = safety or SafetyLimits()
        self.display = display or Display()
        self.period_s = 1.0 / poll_hz
        self.clock = RunClock()
        self.monitor = SafetyMonitor(self.safety, 0.0, drive.limits.speed_max_m_s)
        self.state: DriveState | None = None
        self.profile: DriveProfile | None = None
        self.pipe: RecordingPipe | None = None
        self.drive_ok = True  # False once the drive stopped answering
        self.drive_disabled = False
        self.disable_error = ""
        self.phase = "starting"
        self._next_poll = 0.0
        self._polled = False  # the last pass polled the drive
        self._last_data_s = time.monotonic()
        self._latest = (math.nan, math.nan, math.nan)  # x mm, u mm, F N
        self._checking = True  # safety checks on (off while recording the coast-down)
        self._rate: deque[tuple[float, int]] = deque()
        self._start_s: float | None = None  # host time the profile started
        self._seen = GaugeStats()
        self._checked_stats_s = 0.0
        self._poller: ThreadPoolExecutor | None = None
        self._inflight: Future[DriveState] | None = None
        self._sent_s = 0.0  # when the poll in flight was sent

    # ---- one pass --------------------------------------------------------------------
    def _read(self, timeout_s: float) -> NDArray[np.void] | None:
        try:
            return self.gauges.read_block(timeout_s)
        except (GaugeError, ClosedError) as err:
            raise EStopError(f"the gauge stream failed: {err}") from err

    def _pass(self, expect_active: bool) -> None:
        """Take the queued gauge data, check the silence, poll the drive when due."""
        wait = min(max(self._next_poll - time.monotonic(), 0.0), 0.02)
        blocks = []
        block = self._read(wait)
        while block is not None:
            if len(block):
                blocks.append(block)
            block = self._read(0.0)
        if blocks:
            self._on_gauges(concat_blocks(blocks))
        now = time.monotonic()
        if self._checking:
            self.monitor.check_silence(now - self._last_data_s)
        self._polled = False
        if self._inflight is None and now >= self._next_poll and self.drive_ok:
            self._next_poll = max(self._next_poll + self.period_s, now)
            if self._poller is None:
                self._poller = ThreadPoolExecutor(1, thread_name_prefix="drive poll")
            self._inflight, self._sent_s = self._poller.submit(self.drive.poll), now
            wait_for([self._inflight], timeout=PROMPT_ANSWER_S)
        if self._inflight is not None and self._inflight.done():
            self._poll(expect_active)
        elif self._inflight is not None and time.monotonic() - self._sent_s > DRIVE_ANSWER_S:
            self.drive_ok = False
            raise EStopError(
                f"the drive did not answer: {self.drive.name} gave no reply to a poll "
                f"within {DRIVE_ANSWER_S:g} s"
            )
        self._show()

    def _on_gauges(self, block: NDArray[np.void]) -> None:
        self._last_data_s = int(block["t_host_ns"][-1]) / 1e9
        self.clock.observe(block)
        self._latest = (
            float(block["x_mm"][-1]),
            float(block["u_mm"][-1]),
            float(block["force_n"][-1]),
        )
        self._rate.append((time.monotonic(), len(block)))
        if self.pipe is not None:  # record first: the file holds what triggered a stop
            self.pipe.put_gauges(self.clock.gauges(block), self.clock.command(block, self.profile))
        if self._checking:
            self.monitor.check_block(block)

    def _poll(self, expect_active: bool) -> None:
        """Take the answer of the poll in flight (it is done)."""
        assert self._inflight is not None
        answer, self._inflight = self._inflight, None
        try:
            state = answer.result()
        except DriveError as err:
            self.drive_ok = False
            raise EStopError(f"the drive did not answer: {err}") from err
        self.state, self._polled = state, True
        if self.pipe is not None:
            self.pipe.put_drive(self.clock.drive_row(state))
        if self._checking:
            self.monitor.check_drive(state, expect_active)

    def _event(self, kind: str, text: str) -> None:
        if self.pipe is not None:
            self.pipe.put_event(self.clock.host_ns(time.monotonic()), kind, text)

    def _drain(self) -> None:
        """Discard data queued while nobody read (a confirmation prompt)."""
        while (block := self._read(0.0)) is not None:
            if len(block):
                self.clock.observe(block)
                self._last_data_s = int(block["t_host_ns"][-1]) / 1e9

    def _wait_active(self, timeout_s: float = 1.0) -> None:
        """Pass until a poll shows the drive's output active."""
        deadline = time.monotonic() + timeout_s
        self.state = None
        while self.state is None or not self.state.active:
            if time.monotonic() > deadline:
                raise EStopError(f"{self.drive.name} did not enable within {timeout_s:g} s")
            self._pass(expect_active=False)

    def settle(self, timeout_s: float | None = None) -> None:
        """Wait for the poll in flight before another drive call (the driver is not shared).

        Its answer is dropped; a drive that failed it, or that has not answered within
        ``timeout_s`` (None: the driver's own time-outs), is marked as not answering.
        """
        if self._inflight is None:
            return
        answer, self._inflight = self._inflight, None
        if not wait_for([answer], timeout=timeout_s).done:
            self.drive_ok = False  # in its retries: the worker ends them, nobody waits
            return
        try:
            answer.result()
        except (DriveError, ClosedError):
            self.drive_ok = False

    @contextlib.contextmanager
    def keepalive(self, period_s: float = 0.25) -> Iterator[None]:
        """Poll the drive from a thread while the caller waits (for a confirmation).

        An orderly run stands the watchdog down at its end, but another controller may
        have left it armed; without polls it would trip while the operator reads.
        """
        self.settle()
        done = threading.Event()

        def loop() -> None:
            while not done.wait(period_s):
                try:
                    self.drive.poll()
                except DriveError as err:
                    log.warning("keep-alive poll failed: %s", err)
                    return

        thread = threading.Thread(target=loop, name="drive keep-alive", daemon=True)
        thread.start()
        try:
            yield
        finally:
            done.set()
            thread.join()

    # ---- stopping --------------------------------------------------------------------
    def disable(self) -> bool:
        """Disable the drive at once; True if it acknowledged."""
        self.phase = "disabled"
        self.settle(STOP_SETTLE_S)
        if self.drive.closed:
            return self.drive_disabled
        if not self.drive_ok:  # its time-outs would only delay the stop: the watchdog trips it
            self.disable_error = "the drive does not answer (its watchdog disables it)"
            return False
        try:
            self.drive.disable()
        except (DriveError, ClosedError) as err:
            self.disable_error = str(err)
            # the run's last line says so; the driver's reason goes to the log (-v)
            log.info("could not disable the drive: %s", err)
            return False
        self.drive_disabled, self.disable_error = True, ""
        return True

    def stand_down(self) -> bool:
        """Disable the drive and release its watchdog (it stays healthy); True if done."""
        self.settle()
        if self.drive.closed or not self.drive_ok:
            return False
        try:
            self.drive.stand_down()
        except (DriveError, ClosedError) as err:
            log.error("could not stand the drive's watchdog down: %s", err)
            return False
        self.drive_disabled, self.disable_error, self.phase = True, "", "disabled"
        return True

    def shutdown(self) -> None:
        """Disable the drive and stand its watchdog down, close the devices (idempotent).

        An orderly end (done, Ctrl-C, an e-stop labstand decided) leaves the drive
        disabled and healthy for the next run. A drive that stopped answering cannot be
        told: its watchdog trips it, and the next pre-flight reports that trip.
        """
        try:
            self.settle()
            if not self.drive.closed and self.drive_ok and not self.stand_down():
                self.disable()
        finally:
            if self._poller is not None:
                self._poller.shutdown(wait=True)
            self.drive.close()
            self.gauges.close()

    # ---- display ---------------------------------------------------------------------
    def _elapsed(self) -> float:
        return time.monotonic() - self._start_s if self._start_s is not None else 0.0

    def _show(self, force: bool = False) -> None:
        now = time.monotonic()
        while self._rate and now - self._rate[0][0] > 1.0:
            self._rate.popleft()
        if now - self._checked_stats_s > 0.5 or force:
            self._checked_stats_s = now
            self._gauge_faults()
        x_mm, u_mm, force_n = self._latest
        if math.isnan(x_mm) and not force:
            return  # nothing to show yet
        st = self.state
        drive = "?" if st is None else st.profile_state.name.lower()
        if st is not None and st.tripped:
            drive = f"tripped ({st.trip_name})"
        self.display.update(
            RunStatus(
                phase=self.phase,
                elapsed_s=self._elapsed(),
                total_s=self.profile.duration_s if self.profile else 0.0,
                x_mm=x_mm,
                u_mm=u_mm,
                force_n=force_n,
                rate_hz=float(sum(n for _, n in self._rate)),
                samples=self.pipe.samples if self.pipe else 0,
                lost=self._seen.lost,
                corrupt=self._seen.corrupt,
                drive=drive,
            ),
            force,
        )

    def _gauge_faults(self) -> None:
        """Record new corrupt or lost frames as a 'fault' event (the run goes on)."""
        stats, seen = self.gauges.stats(), self._seen
        if stats.corrupt > seen.corrupt or stats.lost > seen.lost:
            self._event(
                "fault",
                f"gauges: {stats.corrupt - seen.corrupt} corrupt section(s) "
                f"({stats.skipped_bytes - seen.skipped_bytes} bytes skipped), "
                f"{stats.lost - seen.lost} frame(s) lost; the run goes on",
            )
        self._seen = stats
