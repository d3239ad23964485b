"""The run's live display: a rich panel on a terminal, plain lines elsewhere.

``make_display(stream)`` picks ``LiveDisplay`` when the stream is a terminal (elapsed
and remaining time with a progress bar, x, u, F, the sample rate achieved, lost and
corrupt frames, the drive's state) and ``PlainDisplay`` otherwise (one line every few
seconds, for logs and pipes). Both throttle themselves: ``update`` may be called on
every pass of the acquisition loop.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TextIO

from rich.console import Console, Group
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text

from drivers.closing import ClosesOnExit

__all__ = ["Display", "LiveDisplay", "PlainDisplay", "RunStatus", "make_display"]


@dataclass(frozen=True)
class RunStatus:
    """What the display shows.

    Attributes
    ----------
    phase
        "homing", "running", "stopping", ...
    elapsed_s, total_s
        Time since the profile started and the profile's length, s.
    x_mm, u_mm, force_n
        The latest gauge sample (NaN before the first).
    rate_hz
        Samples per second received over the last second, Hz.
    samples, lost, corrupt
        Samples recorded; frames lost (sequence gaps) and corrupt sections so far.
    drive
        The drive's state in a few words.
    viewer
        The live viewer's counts (``labstand.live``), empty without one.
    """

    phase: str
    elapsed_s: float
    total_s: float
    x_mm: float
    u_mm: float
    force_n: float
    rate_hz: float
    samples: int
    lost: int
    corrupt: int
    drive: str
    viewer: str = ""


class Display(ClosesOnExit):
    """No display at all (and the interface of the others)."""

    interval_s = 1.0

    def __init__(self) -> None:
        self._shown = -float("inf")

    def update(self, status: RunStatus, force: bool = False) -> None:
        """Show ``status`` if the last update is older than ``interval_s`` (or force)."""
        now = time.monotonic()
        if force or now - self._shown >= self.interval_s:
            self._shown = now
            self._show(status)

    def _show(self, status: RunStatus) -> None:
        pass

    def close(self) -> None:
        """Leave the terminal as it should be."""


def status_line(s: RunStatus) -> str:
    """The status as one plain line."""
    return (
        f"{s.phase:8s} t {s.elapsed_s:6.1f}/{s.total_s:.1f} s  x {s.x_mm:7.2f} mm  "
        f"u {s.u_mm:7.2f} mm  F {s.force_n:7.1f} N  {s.rate_hz:6.0f} Hz  "
        f"lost {s.lost}  corrupt {s.corrupt}  drive {s.drive}"
        + (f"  {s.viewer}" if s.viewer else "")
    )


class PlainDisplay(Display):
    """One status line every ``interval_s`` seconds (stdout is not a terminal)."""

    def __init__(self, stream: TextIO, interval_s: float = 2.0) -> None:
        super().__init__()
        self.stream = stream
        self.interval_s = interval_s

    def _show(self, status: RunStatus) -> None:
        print(status_line(status), file=self.stream, flush=True)


class LiveDisplay(Display):
    """A rich panel redrawn a few times per second."""

    interval_s = 0.2

    def __init__(self, console: Console) -> None:
        super().__init__()
        self.console = console
        self._progress = Progress(
            TextColumn("{task.description}"),
            BarColumn(bar_width=None),
            TextColumn("{task.completed:5.1f}/{task.total:.1f} s"),
            TimeRemainingColumn(),
            console=console,
            auto_refresh=False,
        )
        self._task = self._progress.add_task("run", total=1.0)
        from rich.live import Live

        self._live = Live(console=console, auto_refresh=False, transient=False)
        self._started = False

    def _render(self, s: RunStatus) -> Group:
        self._progress.update(
            self._task,
            description=s.phase,
            total=max(s.total_s, 1e-9),
            completed=min(max(s.elapsed_s, 0.0), s.total_s),
        )
        table = Table.grid(padding=(0, 3))
        for _ in range(4):
            table.add_column(justify="right")
        table.add_row(
            Text(f"x {s.x_mm:7.2f} mm"),
            Text(f"u {s.u_mm:7.2f} mm"),
            Text(f"F {s.force_n:7.1f} N"),
            Text(f"drive {s.drive}"),
        )
        bad = "bold red" if s.lost or s.corrupt else ""
        table.add_row(
            Text(f"{s.rate_hz:6.0f} Hz"),
            Text(f"{s.samples} samples"),
            Text(f"lost {s.lost}", style=bad),
            Text(f"corrupt {s.corrupt}", style=bad),
        )
        if s.viewer:
            calm = s.viewer.endswith("dropped 0")  # nothing dropped, nothing failed
            table.add_row(Text(s.viewer, style="" if calm else "yellow"))
        return Group(self._progress, table)

    def _show(self, status: RunStatus) -> None:
        self._live.update(self._render(status), refresh=False)
        if not self._started:
            self._live.start(refresh=False)
            self._started = True
        self._live.refresh()

    def close(self) -> None:
        """Stop redrawing; the last panel stays on the screen."""
        if self._started:
            self._live.stop()
            self._started = False


def make_display(stream: TextIO, plain_interval_s: float = 2.0) -> Display:
    """LiveDisplay on a terminal, PlainDisplay otherwise."""
    if stream.isatty():
        return LiveDisplay(Console(file=stream))
    return PlainDisplay(stream, plain_interval_s)
