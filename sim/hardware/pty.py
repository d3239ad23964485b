"""Pseudo-terminals for the simulated stand: a raw pty per serial device, and a bridge.

A program opens the pty's slave path exactly like ``/dev/ttyUSB0``. The simulated device
keeps its own slave descriptor open so the pty lives on while the program reconnects,
and puts the line discipline in raw mode (``tty.setraw``): left cooked, the terminal
rewrites bytes such as CR/LF and corrupts binary frames.

Modbus RTU needs a path at *both* ends (pymodbus opens its server port by name), so the
simulated drive gets two ptys whose masters are bridged byte for byte: the server opens
one slave path, the client the other — the same as ``socat pty,raw,echo=0 pty,raw,echo=0``.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import logging
import os
import tty
from dataclasses import dataclass

log = logging.getLogger(__name__)

__all__ = ["PtyBridge", "RawPty", "open_raw_pty"]


@dataclass
class RawPty:
    """One pseudo-terminal: the device writes the master, programs open ``path``."""

    master_fd: int
    slave_fd: int
    path: str

    def close(self) -> None:
        """Close both ends (idempotent)."""
        for name in ("master_fd", "slave_fd"):
            fd = getattr(self, name)
            if fd >= 0:
                with contextlib.suppress(OSError):
                    os.close(fd)
                setattr(self, name, -1)


def open_raw_pty() -> RawPty:
    """A pty in raw mode with a non-blocking master."""
    master, slave = os.openpty()
    try:
        tty.setraw(slave)
        os.set_blocking(master, False)
        return RawPty(master, slave, os.ttyname(slave))
    except OSError:
        os.close(master)
        os.close(slave)
        raise


class PtyBridge:
    """Two raw ptys whose masters exchange every byte (a null-modem cable).

    Start it inside a running event loop; ``close()`` removes the readers and closes
    the ptys.
    """

    def __init__(self) -> None:
        self.a = open_raw_pty()
        try:
            self.b = open_raw_pty()
        except OSError:
            self.a.close()
            raise
        self._loop: asyncio.AbstractEventLoop | None = None

    def start(self) -> None:
        """Begin copying (call from the event loop's thread)."""
        self._loop = asyncio.get_running_loop()
        self._loop.add_reader(self.a.master_fd, self._copy, self.a, self.b)
        self._loop.add_reader(self.b.master_fd, self._copy, self.b, self.a)

    @staticmethod
    def _copy(src: RawPty, dst: RawPty) -> None:
        try:
            data = os.read(src.master_fd, 4096)
        except OSError as err:
            if err.errno not in {errno.EAGAIN, errno.EIO}:
                log.warning("pty bridge: read %s: %s", src.path, err)
            return
        try:
            os.write(dst.master_fd, data)
        except OSError as err:  # nobody drains the other side: like a cable to nowhere
            if err.errno != errno.EAGAIN:
                log.warning("pty bridge: write %s: %s", dst.path, err)

    def close(self) -> None:
        """Stop copying and close both ptys."""
        if self._loop is not None and not self._loop.is_closed():
            for fd in (self.a.master_fd, self.b.master_fd):
                if fd >= 0:
                    self._loop.remove_reader(fd)
        self._loop = None
        self.a.close()
        self.b.close()
