"""The live view of a run: the server, the feed to it, and their hooks into the run.

``LiveView.open(address, ...)`` starts the Foxglove server (a busy port or a foreign
address: ``CommandError``, exit 2, before any device is touched). The run then gets
its recording pipe from ``LiveView.pipe`` — a ``RecordingPipe`` that also offers each
block, poll and event to the feed (one non-blocking call each) — and its display from
``LiveView.display``, which adds the viewer's drops to the status.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drivers.closing import ClosesOnExit
from labstand.live.address import ViewerAddress
from labstand.live.feed import LiveFeed
from labstand.live.model import LiveModel
from labstand.live.server import LiveServer
from labstand.session.display import Display, RunStatus
from labstand.session.record import RecordingPipe
from recordings.base import RecordingWriter
from sim.params import StandParams

__all__ = ["LiveView", "ObservedPipe", "ViewerDisplay"]


class ObservedPipe(RecordingPipe):
    """A ``RecordingPipe`` that also offers everything it records to a ``LiveFeed``.

    The recording comes first; the offer never blocks (a full feed drops and counts).
    """

    def __init__(self, writer: RecordingWriter, feed: LiveFeed) -> None:
        super().__init__(writer)
        self.feed = feed

    def put_gauges(self, gauges: NDArray[np.void], command: NDArray[np.void]) -> None:
        """Record the block, then offer it to the viewer."""
        super().put_gauges(gauges, command)
        self.feed.offer_gauges(gauges, command)

    def put_drive(self, row: dict[str, Any]) -> None:
        """Record the poll, then offer it to the viewer."""
        super().put_drive(row)
        self.feed.offer_drive(row)

    def put_event(self, t_ns: int, kind: str, text: str = "") -> None:
        """Record the event, then offer it to the viewer."""
        super().put_event(t_ns, kind, text)
        self.feed.offer_event(t_ns, kind, text)


class ViewerDisplay(Display):
    """Another display, with the viewer's counts added to what it shows."""

    def __init__(self, inner: Display, feed: LiveFeed) -> None:
        super().__init__()
        self.inner, self.feed = inner, feed

    def update(self, status: RunStatus, force: bool = False) -> None:
        """The inner display's update, with ``viewer`` filled in."""
        self.inner.update(dataclasses.replace(status, viewer=self.feed.summary()), force)

    def close(self) -> None:
        """Close the inner display."""
        self.inner.close()


class LiveView(ClosesOnExit):
    """A running Foxglove server fed from a run through a bounded queue."""

    def __init__(self, server: LiveServer, feed: LiveFeed) -> None:
        self.server, self.feed = server, feed

    @classmethod
    def open(
        cls, address: ViewerAddress, name: str, params: StandParams | None, rate_hz: float
    ) -> LiveView:
        """Start the server (CommandError, exit 2, if it cannot listen) and the feed."""
        server = LiveServer(address, name)
        model = LiveModel(params, rate_hz) if params is not None else None
        return cls(server, LiveFeed(server, model))

    def pipe(self, writer: RecordingWriter) -> RecordingPipe:
        """The run's recording pipe, observed."""
        return ObservedPipe(writer, self.feed)

    def display(self, inner: Display) -> Display:
        """The run's display, with the viewer's drops."""
        return ViewerDisplay(inner, self.feed)

    def describe(self) -> str:
        """Where to connect, for the run's summary."""
        return f"{self.server.url} (Foxglove: Open connection → Foxglove WebSocket)"

    def close(self) -> None:
        """Publish what is queued, then stop the server (idempotent)."""
        try:
            self.feed.close()
        finally:
            self.server.close()
