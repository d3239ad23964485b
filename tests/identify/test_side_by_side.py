"""Traces side by side: the threads live for one call, and none outlives it."""

from __future__ import annotations

import threading

import numba
import pytest

from sim.identify.side_by_side import side_by_side


def _trace_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name.startswith("trace")]


@pytest.mark.skipif(numba.get_num_threads() < 2, reason="one numba thread runs items in turn")
def test_the_threads_of_a_call_are_gone_when_it_returns() -> None:
    seen: list[str] = []

    def work(k: int, serial: bool) -> int:
        seen.append(threading.current_thread().name)
        return k * k

    assert _trace_threads() == []
    for _ in range(3):  # each call starts its own threads and joins them
        assert side_by_side(work, [1, 3, 2]) == [0, 1, 4]
        assert _trace_threads() == []
    assert all(name.startswith("trace") for name in seen)


def test_a_failing_item_raises_in_the_caller_and_leaves_no_thread() -> None:
    def work(k: int, serial: bool) -> int:
        if k == 1:
            raise ValueError(f"item {k} failed")
        return k

    with pytest.raises(ValueError, match="item 1 failed"):
        side_by_side(work, [2, 2])
    assert _trace_threads() == []
