"""Between the acquisition and the viewer: a bounded queue and a thread of its own.

The session loop hands each gauges block, drive poll and event to ``LiveFeed.offer_*``,
which only ever calls ``put_nowait``: when the queue is full (a viewer thread that
cannot keep up) the item is dropped and counted, the loop goes on. The viewer thread
runs the model beside the measurement and publishes to the ``LiveServer``; any failure
there is logged, counted and the next item taken, so a viewer fault never reaches the
run.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from drivers.closing import ClosesOnExit
from labstand.live.model import LiveModel, ModelBlock

log = logging.getLogger(__name__)

__all__ = ["LiveFeed", "Publisher"]

#: Items (gauge blocks, polls, events) the queue holds: at a block per few ms, seconds.
QUEUE_ITEMS = 2048


class Publisher(Protocol):
    """Where the viewer thread sends things (``LiveServer``)."""

    def gauges(self, block: NDArray[np.void]) -> None:
        """Every sample of a gauges block."""

    def command(self, command: NDArray[np.void]) -> None:
        """The planned drive position at a block's samples."""

    def model(self, t_ns: NDArray[np.int64], block: ModelBlock) -> None:
        """The model and the residual at a block's samples."""

    def drive(self, row: dict[str, Any]) -> None:
        """One drive poll."""

    def event(self, t_ns: int, kind: str, text: str) -> None:
        """One event."""


@dataclass
class _Item:
    kind: str  # gauges | drive | event
    payload: Any
    t_ns: int  # on the recording's axis (a block's last sample)
    wall_ns: int  # when it was offered


@runtime_checkable
class _HasEpoch(Protocol):
    """A publisher whose log times are ``epoch_ns`` + the recording's time."""

    epoch_ns: int


class LiveFeed(ClosesOnExit):
    """A bounded queue from the acquisition to a publishing thread.

    Attributes
    ----------
    dropped
        Gauge samples (and polls, events) the queue had no room for.
    failures
        Items the publisher failed on (logged; the feed goes on).
    published
        Gauge samples handed to the publisher.

    ``wall_ns`` is the wall clock the log times are anchored on (injected in tests).
    """

    def __init__(
        self,
        publisher: Publisher,
        model: LiveModel | None,
        capacity: int = QUEUE_ITEMS,
        wall_ns: Callable[[], int] = time.time_ns,
    ) -> None:
        self.publisher = publisher
        self.model = model
        self.dropped = 0
        self.failures = 0
        self.published = 0
        self._wall_ns = wall_ns
        self._queue: queue.Queue[_Item | None] = queue.Queue(maxsize=capacity)
        self._stop = threading.Event()
        self._anchored: str | None = None  # what set the log times' epoch
        self._thread = threading.Thread(target=self._run, name="foxglove viewer", daemon=True)
        self._thread.start()

    # ---- the acquisition's side: never blocks ------------------------------------
    def _offer(self, kind: str, payload: Any, t_ns: int, count: int) -> None:
        item = _Item(kind, payload, t_ns, self._wall_ns())
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            self.dropped += count

    def offer_gauges(self, gauges: NDArray[np.void], command: NDArray[np.void]) -> None:
        """A gauges block (GAUGES_DTYPE) and the command at its samples."""
        self._offer("gauges", (gauges, command), int(gauges["t_ns"][-1]), len(gauges))

    def offer_drive(self, row: dict[str, Any]) -> None:
        """One drive poll (a ``RunClock.drive_row``; copied, the caller may change it)."""
        self._offer("drive", dict(row), int(row["t_ns"]), 1)

    def offer_event(self, t_ns: int, kind: str, text: str) -> None:
        """One event."""
        self._offer("event", (t_ns, kind, text), t_ns, 1)

    def summary(self) -> str:
        """A few words for the display."""
        text = f"viewer dropped {self.dropped}"
        return text + (f", {self.failures} failed" if self.failures else "")

    # ---- the viewer thread --------------------------------------------------------
    def _run(self) -> None:
        while (item := self._queue.get()) is not None:
            try:
                self._publish(item)
            except Exception as err:  # the viewer never endangers the run
                self.failures += 1
                if self.failures <= 3:
                    log.warning("live view: publishing %s failed: %s", item.kind, err)

    def _anchor(self, publisher: _HasEpoch, item: _Item) -> None:
        """Log time = the recording's time + the smallest (arrival − recording time).

        Gauge blocks set it (their times are the front end's clock): each sample is
        stamped when it could first have arrived, the least-delayed block's lower
        envelope as ``RunClock`` takes it, so it only moves earlier. An item before the
        first block (the operator's note) sets it for the time being.
        """
        epoch = item.wall_ns - item.t_ns
        gauges = item.kind == "gauges"
        if self._anchored is None or (
            gauges and (self._anchored != "gauges" or epoch < publisher.epoch_ns)
        ):
            publisher.epoch_ns = epoch
            self._anchored = "gauges" if gauges else "other"

    def _publish(self, item: _Item) -> None:
        if isinstance(self.publisher, _HasEpoch):
            self._anchor(self.publisher, item)
        if item.kind == "gauges":
            gauges, command = item.payload
            self.publisher.gauges(gauges)
            self.published += len(gauges)
            self.publisher.command(command)
            if self.model is not None:
                self.publisher.model(gauges["t_ns"], self.model.advance(gauges))
        elif item.kind == "drive":
            self.publisher.drive(item.payload)
        else:
            self.publisher.event(*item.payload)

    def close(self, timeout_s: float = 5.0) -> None:
        """Publish what is queued (up to ``timeout_s``), then stop the thread."""
        if self._stop.is_set():
            return
        self._stop.set()
        try:
            self._queue.put(None, timeout=timeout_s)
        except queue.Full:
            log.warning("live view: the viewer thread did not drain in %g s", timeout_s)
            return
        self._thread.join(timeout_s)
