"""The run's recording side: one clock for every stream, and a writer thread.

``RunClock`` puts the gauge front end's clock, the host's clock and the drive's polls
on the recording's time axis (ns since the first recorded sample). ``RecordingPipe``
owns the ``RecordingWriter`` in a thread of its own: the acquisition loop hands it
blocks without ever waiting on the disk, and a writer failure is reported, not raised
into the loop.
"""

from __future__ import annotations

import logging
import queue
import threading
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drivers.closing import ClosesOnExit
from drivers.interfaces import DriveState
from drivers.signals import DriveProfile
from recordings.base import RecordingWriter
from recordings.schema import COMMAND_DTYPE, GAUGES_DTYPE

log = logging.getLogger(__name__)

__all__ = ["RecordingPipe", "RunClock"]


class RunClock:
    """The recording's time axis: int64 ns since the first recorded gauge sample.

    Gauge samples carry the front end's clock (µs); drive polls and events carry the
    host's ``time.monotonic()``. The offset between the two is the smallest
    ``arrival − device time`` seen so far (the least-delayed block), so a USB-serial
    adapter's buffering does not shift the streams against each other.
    """

    def __init__(self) -> None:
        self.t0_us: int | None = None  # device time of the first recorded sample
        self.offset_ns: int | None = None  # host ns − device ns, lower envelope
        self.profile_start_us: float | None = None  # device time the profile started

    def observe(self, block: NDArray[np.void]) -> None:
        """Update the host↔device offset from a block (SAMPLE_DTYPE) just read."""
        offset = int(block["t_host_ns"][-1]) - int(block["t_device_us"][-1]) * 1000
        if self.offset_ns is None or offset < self.offset_ns:
            self.offset_ns = offset

    def host_to_device_us(self, t_host_s: float) -> float:
        """A host ``time.monotonic()`` instant on the device clock, µs."""
        if self.offset_ns is None:
            raise RuntimeError("RunClock: no gauge block observed yet")
        return (t_host_s * 1e9 - self.offset_ns) / 1000.0

    def host_ns(self, t_host_s: float) -> int:
        """A host instant on the recording's axis, ns (0 before the recording starts)."""
        if self.t0_us is None:
            return 0
        return max(round(self.host_to_device_us(t_host_s) * 1000) - self.t0_us * 1000, 0)

    def gauges(self, block: NDArray[np.void]) -> NDArray[np.void]:
        """A block of SAMPLE_DTYPE as the recording's gauges stream (GAUGES_DTYPE)."""
        if self.t0_us is None:
            self.t0_us = int(block["t_device_us"][0])
        out = np.empty(len(block), dtype=GAUGES_DTYPE)
        out["seq"] = block["seq"]
        out["t_ns"] = (block["t_device_us"] - self.t0_us) * 1000
        for name in ("x_mm", "u_mm", "force_n", "flags"):
            out[name] = block[name]
        return out

    def command(self, block: NDArray[np.void], profile: DriveProfile | None) -> NDArray[np.void]:
        """The planned drive position at the block's sample times (0 before the start)."""
        out = np.zeros(len(block), dtype=COMMAND_DTYPE)
        out["t_ns"] = (block["t_device_us"] - (self.t0_us or 0)) * 1000
        if profile is not None and self.profile_start_us is not None:
            t_s = (block["t_device_us"] - self.profile_start_us) / 1e6
            out["x_cmd_mm"] = profile.position_m(t_s) * 1e3
        return out

    def drive_row(self, state: DriveState) -> dict[str, Any]:
        """One poll as a row of the drive stream."""
        return {
            "t_ns": self.host_ns(state.t_host_s),
            "position_mm": state.position_m * 1e3,
            "speed_mm_s": state.velocity_m_s * 1e3,
            "status_word": state.status_word,
            "trip_code": state.trip_code,
            "enabled": state.active,
        }


@dataclass
class _Item:
    kind: str  # gauges | drive | event
    payload: Any


class RecordingPipe(ClosesOnExit):
    """A RecordingWriter fed through a queue by a thread of its own.

    ``put_*`` never block (the queue is unbounded: the writer is two orders of magnitude
    faster than 2 kHz, docs/recording-format.md §7). Times of drive rows and events are
    made non-decreasing here, as the schema demands. ``close()`` writes everything queued
    and closes the file; a writer failure is kept in ``error`` and later items are
    dropped, so the acquisition can stop in order.
    """

    def __init__(self, writer: RecordingWriter) -> None:
        self.writer = writer
        self.path = writer.path
        self.error: BaseException | None = None
        self.samples = 0
        self.t_last_ns = 0
        self._queue: queue.SimpleQueue[_Item | None] = queue.SimpleQueue()
        self._last_drive_ns = 0
        self._last_event_ns = 0
        self._thread = threading.Thread(target=self._run, name="recording writer", daemon=True)
        self._thread.start()

    def put_gauges(self, gauges: NDArray[np.void], command: NDArray[np.void]) -> None:
        """Queue a gauges block and the command at the same sample times."""
        self.samples += len(gauges)
        self.t_last_ns = int(gauges["t_ns"][-1])
        self._queue.put(_Item("gauges", (gauges, command)))

    def put_drive(self, row: dict[str, Any]) -> None:
        """Queue one drive poll (a ``RunClock.drive_row``)."""
        row["t_ns"] = self._last_drive_ns = max(int(row["t_ns"]), self._last_drive_ns)
        self._queue.put(_Item("drive", row))

    def put_event(self, t_ns: int, kind: str, text: str = "") -> None:
        """Queue one event."""
        self._last_event_ns = max(int(t_ns), self._last_event_ns)
        self._queue.put(_Item("event", (self._last_event_ns, kind, text)))
        log.info("event %s at %.3f s: %s", kind, self._last_event_ns / 1e9, text)

    def _run(self) -> None:
        while (item := self._queue.get()) is not None:
            if self.error is not None:
                continue
            try:
                self._write(item)
            except Exception as err:  # disk full, bad data: reported to the loop
                log.error("%s: writing failed: %s", self.path, err)
                self.error = err

    def _write(self, item: _Item) -> None:
        if item.kind == "gauges":
            gauges, command = item.payload
            self.writer.write_gauges(gauges)
            self.writer.write_command(command)
        elif item.kind == "drive":
            self.writer.write_drive_state(item.payload)
        else:
            self.writer.write_event(*item.payload)

    def close(self, timeout_s: float = 30.0) -> None:
        """Write what is queued, then close the file (idempotent)."""
        if self._thread.is_alive():
            self._queue.put(None)
            self._thread.join(timeout_s)
        if self._thread.is_alive():  # pragma: no cover - a disk that hangs
            log.error("%s: the writer thread did not finish in %g s", self.path, timeout_s)
            return
        try:
            self.writer.close()
        except Exception as err:
            self.error = self.error or err
            raise
