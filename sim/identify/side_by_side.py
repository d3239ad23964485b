"""One parameter set over several traces: the traces side by side, one thread each.

A batch of many parameter sets fills the cores within each trace (every set and segment
is a work item). A single set does not: the slow recording, never slack, is one segment
on one core, and a model whose states carry from segment to segment runs its whole trace
on one core. Run one after the other, the traces then leave a core idle most of the
time. Side by side, each trace runs on its own thread through the kernels' serial
GIL-free variants (``serial=True``), the longest first; the outputs are bit for bit those
of the parallel kernels, which compute every item alike.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

import numba

from sim.model import in_serial_lane, serial_lane

T = TypeVar("T")

__all__ = ["in_lanes", "side_by_side"]


def side_by_side(work: Callable[[int, bool], T], sizes: Sequence[int]) -> list[T]:
    """``work(k, serial)`` for every item k (``sizes[k]``: its cost), results in order.

    With more than one numba thread and more than one item, the items run in threads
    (largest first) with ``serial`` True; otherwise one after the other with ``serial``
    False (on all cores each). The threads live for this call only (started and joined
    here: no pool outlives it, so no state is shared between calls); that costs about
    0.5 ms a call against some 20 ms of work (docs/benchmarks.md).
    """
    if in_serial_lane():  # already one of several lanes: the cores are taken
        return [work(k, True) for k in range(len(sizes))]
    threads = min(len(sizes), numba.get_num_threads())
    if threads < 2:
        return [work(k, False) for k in range(len(sizes))]
    order = sorted(range(len(sizes)), key=lambda k: -sizes[k])
    with ThreadPoolExecutor(max_workers=threads, thread_name_prefix="trace") as pool:
        futures = {k: pool.submit(work, k, True) for k in order}
        return [futures[k].result() for k in range(len(sizes))]


def in_lanes(work: Callable[[int], T], sizes: Sequence[float]) -> list[T]:
    """``work(k)`` for every item k (``sizes[k]``: its guessed cost), results in order.

    For independent pieces that each run many batches (a candidate's refit, a bootstrap
    replicate): with more than one numba thread they run in threads, each a serial lane
    (``sim.physics.lanes``: its runs on its own thread), the costliest first. A batch
    on all cores leaves them idle while Python prepares the next one and while a model
    whose states carry runs a segment after another; lanes fill those gaps with another
    piece's runs. The numbers are those of one after the other. Inside a lane, or with
    one thread, the items run one after the other here.
    """
    threads = min(len(sizes), numba.get_num_threads())
    if threads < 2 or in_serial_lane():
        return [work(k) for k in range(len(sizes))]

    stop = threading.Event()

    def lane(k: int) -> T:
        with serial_lane(stop):
            return work(k)

    order = sorted(range(len(sizes)), key=lambda k: -sizes[k])
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="lane")
    try:
        futures = {k: pool.submit(lane, k) for k in order}
        return [futures[k].result() for k in range(len(sizes))]
    finally:
        # On a failure (or Ctrl-C, SIGTERM) the pieces not yet started are dropped and
        # those running stop at their next run (``LaneStoppedError``, unread): the call returns
        # after one run of each, not a whole refit. Their threads are joined here.
        stop.set()
        pool.shutdown(wait=True, cancel_futures=True)
