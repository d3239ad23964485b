"""Progress of many jobs on stderr: a bar with done/total and ETA, or one line per job."""

from __future__ import annotations

import sys
import time
from typing import TextIO

BAR_WIDTH = 28


def _clock(seconds: float) -> str:
    s = round(seconds)
    return f"{s // 3600:d}:{s % 3600 // 60:02d}:{s % 60:02d}"


class Progress:
    """Reports jobs as they finish.

    On a terminal a bar redrawn in place; elsewhere (a log file, a pipe) one line per job
    so nothing is lost. ``quiet`` (``--json``) says nothing but the messages passed to
    ``say`` with ``always=True``.
    """

    def __init__(
        self, label: str, total: int, quiet: bool = False, stream: TextIO | None = None
    ) -> None:
        self.label = label
        self.total = total
        self.done = 0
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        self.started = time.monotonic()
        self._bar = not quiet and self.stream.isatty()

    def say(self, message: str, always: bool = False) -> None:
        """A line of its own (above the bar)."""
        if self.quiet and not always:
            return
        self._clear()
        print(f"{self.label}: {message}", file=self.stream, flush=True)
        self._draw()

    def eta_s(self) -> float | None:
        """Seconds left at the rate so far (None before the first job finished)."""
        if self.done == 0:
            return None
        elapsed = time.monotonic() - self.started
        return elapsed / self.done * (self.total - self.done)

    def advance(self, what: str) -> None:
        """One job finished; ``what`` says how."""
        self.done += 1
        if self.quiet:
            return
        eta = self.eta_s()
        left = "" if eta is None or self.done == self.total else f", ETA {_clock(eta)}"
        if self._bar:
            self._clear()
            print(f"{self.label}: {what}", file=self.stream, flush=True)
            self._draw()
        else:
            print(f"{self.label}: [{self.done}/{self.total}{left}] {what}", file=self.stream,
                  flush=True)  # fmt: skip

    def close(self) -> None:
        """End the bar's line."""
        if self._bar:
            self._clear()
            self._bar = False

    def _draw(self) -> None:
        if not self._bar:
            return
        filled = BAR_WIDTH * self.done // max(self.total, 1)
        eta = self.eta_s()
        left = "ETA --:--:--" if eta is None else f"ETA {_clock(eta)}"
        bar = "#" * filled + "." * (BAR_WIDTH - filled)
        self.stream.write(f"\r[{bar}] {self.done}/{self.total} {left} ")
        self.stream.flush()

    def _clear(self) -> None:
        if self._bar:
            self.stream.write("\r\033[K")
            self.stream.flush()
