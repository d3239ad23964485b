"""Ctrl-C remembered as well as raised (for code that waits inside libraries)."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def remembered_interrupt() -> Iterator[threading.Event]:
    """Ctrl-C remembered as well as raised, for the ``with`` block (main thread only).

    A KeyboardInterrupt raised inside a library's own waiting (Dask starting workers or
    waiting for results, the Foxglove server's native code) can be lost there: a run went
    on to finish every job after Ctrl-C, a ``play --loop`` never ended. The event lets
    the caller raise it again where it looks.
    """
    event = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield event
        return

    def on_interrupt(signum: int, frame: object) -> None:
        event.set()
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, on_interrupt)
    try:
        yield event
    finally:
        signal.signal(signal.SIGINT, previous)
