"""A linked pair of raw pseudo-terminals made by socat (the RTU tests' serial line)."""

from __future__ import annotations

import shutil
import signal
import subprocess
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest


@contextmanager
def socat_ptys(folder: Path) -> Iterator[tuple[str, str]]:
    """Two linked raw ptys in ``folder``: (server end, client end); socat ends with it."""
    if shutil.which("socat") is None:
        pytest.fail("socat is not installed (make system-tools installs it)")
    a, b = folder / "ptyA", folder / "ptyB"
    proc = subprocess.Popen(
        ["socat", f"pty,raw,echo=0,link={a}", f"pty,raw,echo=0,link={b}"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 5.0
    while not (a.exists() and b.exists()):
        if time.monotonic() > deadline or proc.poll() is not None:
            proc.kill()
            proc.wait()
            pytest.fail("socat did not create its pty pair")
        time.sleep(0.01)
    try:
        yield str(a), str(b)
    finally:
        proc.terminate()
        proc.wait(5)


@contextmanager
def sigint_not_ignored() -> Iterator[None]:
    """Around starting a child that a test interrupts with SIGINT (Ctrl-C).

    A child inherits an ignored SIGINT, and Python then never raises KeyboardInterrupt:
    under the whole suite (but in no module alone) an interrupted child ran on to its
    end. While this is open, SIGINT in this process is caught (not ignored), so a child
    started here gets it at its default, as from a terminal.
    """
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
