"""Ctrl-C remembered as well as raised (for code that waits inside libraries)."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def remembered_interrupt(raise_now: bool = True) -> Iterator[threading.Event]:
    """Ctrl-C remembered as well as raised, for the ``with`` block (main thread only).

    A KeyboardInterrupt raised inside a library's own waiting (Dask starting workers or
    waiting for results, the Foxglove server's native code) can be lost there: a run went
    on to finish every job after Ctrl-C, a ``play --loop`` never ended. The event lets
    the caller raise it again where it looks. Without ``raise_now`` Ctrl-C is only
    remembered: for short work that must not stop halfway (a Dask future whose
    construction it interrupted failed in its ``__del__`` at exit, a traceback after
    "labstand: interrupted").
    """
    event = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield event
        return

    def on_interrupt(signum: int, frame: object) -> None:
        event.set()
        if raise_now:
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, on_interrupt)
    try:
        yield event
    finally:
        signal.signal(signal.SIGINT, previous)
