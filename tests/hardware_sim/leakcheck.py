"""A fixture that fails a test which leaves a thread, a file descriptor or a child behind.

Servers, ptys and serial ports are file descriptors, so an open port or a listening
socket shows up as a leaked descriptor. Resources may take a moment to go (a thread
finishing its last read), so the check polls with a short deadline before failing.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

GRACE_S = 3.0


def gone(pid: int) -> bool:
    """The process has exited (a zombie of a dead parent counts as exited)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return True
    return state in {"Z", "X"}


def _fds() -> dict[int, str]:
    out = {}
    for entry in Path("/proc/self/fd").iterdir():
        try:
            out[int(entry.name)] = os.readlink(entry)
        except OSError:
            continue
    return out


def _children() -> set[int]:
    me = str(os.getpid())
    kids = set()
    for task in Path(f"/proc/{me}/task").iterdir():
        try:
            kids |= {int(p) for p in (task / "children").read_text().split()}
        except OSError:
            continue
    return kids


def _threads() -> set[threading.Thread]:
    return {t for t in threading.enumerate() if t.is_alive()}


@pytest.fixture(autouse=True)
def no_leaks() -> Iterator[None]:
    """Fail the test if it leaves threads, file descriptors or child processes."""
    threads, fds, kids = _threads(), _fds(), _children()
    yield
    deadline = time.monotonic() + GRACE_S
    while True:
        new_threads = _threads() - threads
        now = _fds()
        new_fds = {fd: target for fd, target in now.items() if fds.get(fd) != target}
        new_kids = _children() - kids
        if not (new_threads or new_fds or new_kids):
            return
        if time.monotonic() > deadline:
            break
        time.sleep(0.02)
    problems = []
    if new_threads:
        problems.append(f"threads left running: {sorted(t.name for t in new_threads)}")
    if new_fds:
        problems.append(f"file descriptors left open: {new_fds}")
    if new_kids:
        problems.append(f"child processes left running: {sorted(new_kids)}")
    pytest.fail("; ".join(problems))
