"""Ctrl-C while the jobs are being submitted: every future is whole, and the run stops."""

from __future__ import annotations

import io
import os
import signal
from typing import Any

import pytest

from labstand.distributed import Progress
from labstand.distributed.jobs import run_jobs
from labstand.interrupts import remembered_interrupt


class _Future:
    def __init__(self, key: str) -> None:
        self.key = key

    def done(self) -> bool:
        return False


class _Client:
    """Takes submissions; Ctrl-C arrives in the middle of the second (as from a terminal)."""

    def __init__(self) -> None:
        self.submitted: list[_Future] = []
        self.cancelled: list[_Future] = []

    def submit(self, *args: Any, key: str, **kwargs: Any) -> _Future:
        if len(self.submitted) == 1:
            os.kill(os.getpid(), signal.SIGINT)
        future = _Future(key)  # a Dask future half-built here failed in its __del__
        self.submitted.append(future)
        return future

    def cancel(self, futures: list[_Future]) -> None:
        self.cancelled += futures


def test_ctrl_c_during_submission_waits_for_the_whole_future_then_stops() -> None:
    client = _Client()
    progress = Progress("labstand diagnose", 3, stream=io.StringIO())
    with pytest.raises(KeyboardInterrupt):
        run_jobs(client, str, ["a", "b", "c"], ["a", "b", "c"], progress)  # type: ignore[arg-type]
    assert len(client.submitted) == 3  # none cut off halfway
    assert client.cancelled == client.submitted  # and none left running


def test_a_remembered_ctrl_c_raises_at_once_unless_told_to_wait() -> None:
    with remembered_interrupt(raise_now=False) as later:
        os.kill(os.getpid(), signal.SIGINT)
        finished = True
    assert finished and later.is_set()
    with pytest.raises(KeyboardInterrupt), remembered_interrupt() as now:
        os.kill(os.getpid(), signal.SIGINT)
        pytest.fail("Ctrl-C did not stop the block")
    assert now.is_set()
