"""Traces side by side: threads started per call against one process-wide pool.

    .venv/bin/python benchmarks/bench_side_by_side.py [--calls 2000] [--diagnosis]

``side_by_side`` starts and joins its threads in every call (no pool outlives a call);
the reference is the process-wide pool it kept before (``functools.cache`` of a
``ThreadPoolExecutor``), reproduced here. Both run the same empty items, 2, 3 and 4 per
call, alternately in blocks, so the figure is the overhead alone. ``--diagnosis`` also
counts the calls of one diagnosis and the time spent in them: the half-length campaign
of ``bench_diagnosis.py`` (three recordings, heavy weight, seed 3), warmed first.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from functools import cache

import numba

from sim.identify.side_by_side import side_by_side


@cache
def _pool(threads: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=threads, thread_name_prefix="trace")


def process_wide(work: Callable[[int, bool], int], sizes: Sequence[int]) -> list[int]:
    """The reference: ``side_by_side`` as it was, with the pool kept for the process."""
    pool = _pool(min(len(sizes), numba.get_num_threads()))
    futures = {k: pool.submit(work, k, True) for k in range(len(sizes))}
    return [futures[k].result() for k in range(len(sizes))]


def _item(k: int, serial: bool) -> int:
    return k


def per_call_us(run: Callable[..., list[int]], items: int, calls: int) -> float:
    started = time.perf_counter()
    for _ in range(calls):
        run(_item, [1] * items)
    return (time.perf_counter() - started) / calls * 1e6


def count_in_diagnosis() -> None:
    import numpy as np
    from bench_diagnosis import campaign

    import sim.identify.fitting as fitting
    import sim.identify.screening as screening
    from sim.checks.check import make_campaign
    from sim.config import default_config
    from sim.identify import diagnose

    spent: list[float] = []

    def counted(work: Callable[[int, bool], object], sizes: Sequence[int]) -> list[object]:
        started = time.perf_counter()
        out = side_by_side(work, sizes)
        spent.append(time.perf_counter() - started)
        return out

    fitting.side_by_side = screening.side_by_side = counted  # type: ignore[assignment]
    stand = default_config()
    nominal = stand.stand_params("final", 8.131)
    rng = np.random.default_rng(3)
    traces, _, _ = make_campaign(stand, "fibre_viscoelastic", 8.131, rng, campaign(0.5))
    diagnose(traces[:1], nominal, candidates=["dial_gauge_calibration"])  # warm the kernels
    spent.clear()
    started = time.perf_counter()
    diagnose(traces, nominal)
    wall = time.perf_counter() - started
    print(
        f"a diagnosis of {len(traces)} recordings: {wall:.1f} s, {len(spent)} calls of "
        f"side_by_side, {sum(spent):.1f} s in them (mean {statistics.mean(spent) * 1e3:.1f} ms)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--calls", type=int, default=2000, help="calls per block")
    parser.add_argument("--diagnosis", action="store_true", help="count a diagnosis' calls")
    args = parser.parse_args()
    if numba.get_num_threads() < 2:
        sys.exit("one numba thread: side_by_side runs the items in turn, nothing to measure")
    print(f"{numba.get_num_threads()} numba threads; µs per call, median of 5 blocks\n")
    print("| items per call | one pool for the process (before) | threads per call (now) |")
    print("|---|---|---|")
    for items in (2, 3, 4):
        old, new = [], []
        for _ in range(5):
            old.append(per_call_us(process_wide, items, args.calls))
            new.append(per_call_us(side_by_side, items, args.calls))
        print(f"| {items} | {statistics.median(old):.0f} | {statistics.median(new):.0f} |")
    if args.diagnosis:
        count_in_diagnosis()


if __name__ == "__main__":
    main()
