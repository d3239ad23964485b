"""Serial lanes: a thread whose every run stays on it (used through ``sim.model``).

Several independent pieces of work (candidates' refits, bootstrap replicates) can run
side by side, one thread each, instead of one after the other on all cores. Inside such
a lane every run takes the kernels' serial GIL-free variants, and work that would itself
spread over threads (``sim.identify.side_by_side``) runs in order on the lane: a lane
never starts threads of its own, so the cores are never oversubscribed. The serial and
parallel kernels compute every item alike, so a lane changes the time, not the numbers.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["LaneStoppedError", "in_serial_lane", "serial_lane", "stop_if_asked"]

_HERE = threading.local()


class LaneStoppedError(Exception):
    """The lanes' caller gave up (another lane failed, Ctrl-C, SIGTERM): this one stops."""


@contextmanager
def serial_lane(stop: threading.Event | None = None) -> Iterator[None]:
    """Every run on the calling thread inside this block is serial.

    ``stop``: once set, the lane's next run raises ``LaneStoppedError`` (``stop_if_asked``), so a
    caller that gives up waits for one run of each lane, not for each lane's whole work.
    """
    before = getattr(_HERE, "serial", False), getattr(_HERE, "stop", None)
    _HERE.serial, _HERE.stop = True, stop
    try:
        yield
    finally:
        _HERE.serial, _HERE.stop = before


def stop_if_asked() -> None:
    """Raise ``LaneStoppedError`` where the calling thread's lane was told to stop."""
    stop = getattr(_HERE, "stop", None)
    if stop is not None and stop.is_set():
        raise LaneStoppedError("the lanes' caller gave up")


def in_serial_lane() -> bool:
    """Whether the calling thread is inside ``serial_lane``."""
    return bool(getattr(_HERE, "serial", False))
