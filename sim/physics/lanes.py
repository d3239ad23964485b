"""Serial lanes: a thread whose every run stays on it (private: ``sim.physics.runs``).

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

__all__ = ["in_serial_lane", "serial_lane"]

_HERE = threading.local()


@contextmanager
def serial_lane() -> Iterator[None]:
    """Every run on the calling thread inside this block is serial."""
    before = getattr(_HERE, "serial", False)
    _HERE.serial = True
    try:
        yield
    finally:
        _HERE.serial = before


def in_serial_lane() -> bool:
    """Whether the calling thread is inside ``serial_lane``."""
    return bool(getattr(_HERE, "serial", False))
