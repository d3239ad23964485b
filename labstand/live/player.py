"""A recording played to the live server at real time (or ``speed`` times), on a clock.

``Player`` walks the recording's gauges in blocks of ``BLOCK_S`` and, between them, the
drive polls and events due by then, in time order, and hands them to a ``Publisher``
(the ``LiveServer``) when the clock reaches their time; the model runs beside the
gauges as during a live run. The clock is injected: ``WallClock`` for ``labstand play``,
a simulated one in tests, which so run the whole recording at once.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from labstand.live.feed import Publisher
from labstand.live.model import LiveModel
from recordings import Recording
from sim.params import StandParams

__all__ = ["BLOCK_S", "Clock", "Player", "WallClock"]

#: Gauge samples published together, s of recording (the live run's blocks are smaller).
BLOCK_S = 0.02


class Clock(Protocol):
    """Where the player's time comes from."""

    def now(self) -> float:
        """Seconds on a monotonic clock."""
        ...

    def sleep(self, seconds: float) -> None:
        """Wait that long."""
        ...


class WallClock:
    """The real clock."""

    def now(self) -> float:
        """``time.monotonic()``."""
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        """``time.sleep``."""
        time.sleep(seconds)


class Stopper(Protocol):
    """Asked between blocks whether to stop (Ctrl-C)."""

    def __call__(self) -> bool: ...


@dataclass
class PlayStats:
    """What one pass published."""

    samples: int = 0
    drive: int = 0
    events: int = 0


class Player:
    """Plays ``recording`` to ``publisher`` from ``start_s`` at ``speed``× real time.

    ``params`` (None: no model) are the model's; it restarts at rest with each pass.
    """

    def __init__(
        self,
        recording: Recording,
        publisher: Publisher,
        params: StandParams | None,
        clock: Clock,
        speed: float = 1.0,
        start_s: float = 0.0,
    ) -> None:
        if not speed > 0:
            raise ValueError(f"--speed must be > 0, got {speed:g}")
        duration = recording.duration_s
        if not 0 <= start_s < duration:
            raise ValueError(
                f"--start {start_s:g} s is outside the recording (0 … {duration:.3f} s)"
            )
        self.recording, self.publisher, self.params = recording, publisher, params
        self.clock, self.speed = clock, speed
        g = recording.gauges
        self.start_ns = int(g["t_ns"][0]) + round(start_s * 1e9)
        self._first = int(np.searchsorted(g["t_ns"], self.start_ns))
        self.rate_hz = recording.metadata.sample_rate_hz

    def _wait(self, t0: float, t_ns: int) -> None:
        due = t0 + (t_ns - self.start_ns) / 1e9 / self.speed
        delay = due - self.clock.now()
        if delay > 0:
            self.clock.sleep(delay)

    def play(self, stop: Stopper | None = None) -> PlayStats:
        """One pass from ``start_s`` to the end (or until ``stop()``)."""
        rec, stats = self.recording, PlayStats()
        g, command = rec.gauges, rec.command
        model = LiveModel(self.params, self.rate_hz) if self.params is not None else None
        drive = rec.drive[rec.drive["t_ns"] >= self.start_ns]
        events = rec.events_array[rec.events_array["t_ns"] >= self.start_ns]
        i_drive = i_event = 0
        step = max(round(BLOCK_S * self.rate_hz), 1)
        t0 = self.clock.now()
        for lo in range(self._first, len(g), step):
            if stop is not None and stop():
                break
            block = g[lo : lo + step]
            t_end = int(block["t_ns"][-1])
            while i_drive < len(drive) and drive["t_ns"][i_drive] <= t_end:
                self.publisher.drive(_row(drive[i_drive]))
                i_drive += 1
            while i_event < len(events) and events["t_ns"][i_event] <= t_end:
                e = events[i_event]
                self.publisher.event(int(e["t_ns"]), str(e["kind"]), str(e["text"]))
                i_event += 1
            self._wait(t0, t_end)
            self.publisher.gauges(block)
            self.publisher.command(_command_at(command, block))
            if model is not None:
                self.publisher.model(block["t_ns"], model.advance(block))
            stats.samples += len(block)
        if stop is None or not stop():  # after the last sample: the final polls and note
            for t_ns, kind, text in events[i_event:].tolist():
                while i_drive < len(drive) and drive["t_ns"][i_drive] <= t_ns:
                    self.publisher.drive(_row(drive[i_drive]))
                    i_drive += 1
                self._wait(t0, int(t_ns))
                self.publisher.event(int(t_ns), str(kind), str(text))
                i_event += 1
            for row in drive[i_drive:]:
                self.publisher.drive(_row(row))
                i_drive += 1
        stats.drive, stats.events = i_drive, i_event
        return stats

    @property
    def span_ns(self) -> int:
        """Recording time one pass covers (to the last sample, poll or event), ns."""
        rec = self.recording
        last = [int(a["t_ns"][-1]) for a in (rec.gauges, rec.drive, rec.events_array) if len(a)]
        return max(last) - self.start_ns


def _row(row: np.void) -> dict[str, Any]:
    return {name: row[name].item() for name in row.dtype.names or ()}


def _command_at(command: NDArray[np.void], block: NDArray[np.void]) -> NDArray[np.void]:
    """The command rows within the block's time span."""
    lo = int(np.searchsorted(command["t_ns"], block["t_ns"][0], side="left"))
    hi = int(np.searchsorted(command["t_ns"], block["t_ns"][-1], side="right"))
    return command[lo:hi]
