"""Progress of many jobs on stderr: a rich bar with done/total and ETA, or one line per job."""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:  # rich is imported when a bar is drawn (a terminal), not with this module
    import rich.progress


def _clock(seconds: float) -> str:
    s = round(seconds)
    return f"{s // 3600:d}:{s % 3600 // 60:02d}:{s % 60:02d}"


class Progress:
    """Reports jobs as they finish.

    On a terminal a rich progress bar (as the run's live panel) with each job's line
    printed above it; elsewhere (a log file, a pipe) one line per job so nothing is lost.
    ``quiet`` (``--json``) says nothing but the messages passed to ``say`` with
    ``always=True``.
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
        self._bar: rich.progress.Progress | None = None
        if not quiet and self.stream.isatty():
            self._bar = self._start_bar()

    def _start_bar(self) -> rich.progress.Progress:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            TextColumn,
            TimeRemainingColumn,
        )
        from rich.progress import Progress as Bar

        bar = Bar(
            TextColumn("{task.description}", markup=False),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            console=Console(file=self.stream, highlight=False),
            transient=True,  # closed: the bar's line goes, the jobs' lines stay
        )
        self._task = bar.add_task(self.label, total=self.total)
        bar.start()
        return bar

    def say(self, message: str, always: bool = False) -> None:
        """A line of its own (above the bar)."""
        if self.quiet and not always:
            return
        self._line(f"{self.label}: {message}")

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
        if self._bar is not None:
            self._line(f"{self.label}: {what}")
            self._bar.update(self._task, completed=self.done)
            return
        eta = self.eta_s()
        left = "" if eta is None or self.done == self.total else f", ETA {_clock(eta)}"
        print(f"{self.label}: [{self.done}/{self.total}{left}] {what}", file=self.stream,
              flush=True)  # fmt: skip

    def close(self) -> None:
        """Stop the bar (its line is cleared)."""
        if self._bar is not None:
            self._bar.stop()
            self._bar = None

    def _line(self, text: str) -> None:
        if self._bar is not None:
            self._bar.console.print(text, markup=False, highlight=False, soft_wrap=True)
        else:
            print(text, file=self.stream, flush=True)
