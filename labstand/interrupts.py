"""Ctrl-C remembered as well as raised (for code that waits inside libraries).

SIGTERM is raised as ``Terminated`` (a KeyboardInterrupt), so every command ends it as it
ends a Ctrl-C (cleanly) and says which it was: exit 143, "terminated".
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from types import FrameType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from labstand.session import StopRequest


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread: handled wherever a Ctrl-C is, named apart."""


def _raise_terminated(signum: int, frame: object) -> None:
    raise Terminated


@contextmanager
def sigterm_raises() -> Iterator[None]:
    """SIGTERM raises ``Terminated`` in the main thread, for the ``with`` block (a command)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


class Interrupt(threading.Event):
    """A remembered Ctrl-C or SIGTERM: ``raise_it`` raises the one that came."""

    terminated = False

    def raise_it(self) -> None:
        """Raise Terminated for a SIGTERM, KeyboardInterrupt for a Ctrl-C."""
        raise Terminated if self.terminated else KeyboardInterrupt


@contextmanager
def remembered_interrupt(raise_now: bool = True) -> Iterator[Interrupt]:
    """Ctrl-C remembered as well as raised, for the ``with`` block (main thread only).

    A KeyboardInterrupt raised inside a library's own waiting (Dask starting workers or
    waiting for results, the Foxglove server's native code) can be lost there: a run went
    on to finish every job after Ctrl-C, a ``play --loop`` never ended. The event lets
    the caller raise it again where it looks. Without ``raise_now`` Ctrl-C is only
    remembered: for short work that must not stop halfway (a Dask future whose
    construction it interrupted failed in its ``__del__`` at exit, a traceback after
    "labstand: interrupted").
    """
    event = Interrupt()
    if threading.current_thread() is not threading.main_thread():
        yield event
        return

    def on_interrupt(signum: int, frame: object) -> None:
        event.terminated = event.terminated or signum == signal.SIGTERM
        event.set()
        if raise_now:
            event.raise_it()

    previous = {s: signal.signal(s, on_interrupt) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield event
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


@contextmanager
def stop_presses(stop: StopRequest) -> Iterator[None]:
    """Ctrl-C (and SIGTERM) count presses instead of raising, while the drive may move."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: FrameType | None) -> None:
        stop.press("SIGTERM" if signum == signal.SIGTERM else "Ctrl-C")
        text = (
            f"\nlabstand: {stop.by}: stopping in order (again: disable the drive at once)\n"
            if stop.presses == 1
            else "\nlabstand: disabling the drive at once\n"
        )
        with suppress(OSError):
            os.write(sys.stderr.fileno(), text.encode())

    old = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, previous in old.items():
            signal.signal(sig, previous)
