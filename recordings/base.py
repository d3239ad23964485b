"""The writer ABC, the stream checks, and ``open_writer`` (the format by its suffix).

Writers stream: each ``write_*`` call appends a block and the file is pushed to the
operating system at least every ``flush_interval_s`` of data (and of wall time), so a
killed process loses at most the last second. A writer is thread-confined: one thread
(the acquisition's writer thread) makes every call.
"""

from __future__ import annotations

import logging
import math
import time
from abc import ABC, abstractmethod
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drivers.closing import ClosesOnExit
from recordings.errors import InvalidDataError, WriterClosedError
from recordings.formats import writer_for
from recordings.schema import (
    COMMAND_DTYPE,
    DRIVE_DTYPE,
    GAUGES_DTYPE,
    MAX_RUN_TIME_NS,
    Block,
    RecordingMetadata,
    as_block,
)

__all__ = ["EVENTS_DTYPE", "RecordingWriter", "check_stream", "open_writer"]

log = logging.getLogger(__name__)

#: Events in memory: the strings as Python objects.
EVENTS_DTYPE = np.dtype([("t_ns", "<i8"), ("kind", object), ("text", object)])
_FLOAT_FIELDS = {"gauges": ("x_mm", "u_mm", "force_n"), "command": ("x_cmd_mm",)}
_FLOAT_FIELDS["drive"] = ("position_mm", "speed_mm_s")


def check_stream(where: str, stream: str, block: NDArray[np.void], strict: bool = True) -> None:
    """Raise InvalidDataError for NaNs or times that do not increase.

    ``strict`` demands strictly increasing ``t_ns`` (and ``seq``); otherwise
    non-decreasing (the drive and event streams may share a timestamp). The common case
    costs a few whole-array reductions: the sum of finite values is finite.
    """
    if len(block) == 0:
        return
    floats = _FLOAT_FIELDS.get(stream, ())
    with np.errstate(over="ignore"):  # finite values whose sum overflows: checked one by one
        total = float(sum(block[name].sum() for name in floats)) if floats else 0.0
    if not math.isfinite(total):
        for name in floats:
            bad = ~np.isfinite(block[name])
            if bad.any():
                i = int(np.argmax(bad))
                t_s = block["t_ns"][i] / 1e9
                raise InvalidDataError(
                    f"{where}: {stream}.{name} is not finite at sample {i} (t = {t_s:.6f} s)"
                )
    for name in ("t_ns", "seq") if stream == "gauges" else ("t_ns",):
        values = block[name]
        ok = values[1:] > values[:-1] if strict else values[1:] >= values[:-1]
        if not ok.all():
            i = int(np.argmin(ok))
            raise InvalidDataError(
                f"{where}: {stream}.{name} does not increase at sample {i + 1} "
                f"({int(values[i])} then {int(values[i + 1])})"
            )


def _check_time_range(where: str, stream: str, first_ns: int, last_ns: int) -> None:
    """Refuse times beyond ±MAX_RUN_TIME_NS (104 days) of the start, for every format."""
    if not (first_ns >= -MAX_RUN_TIME_NS and last_ns <= MAX_RUN_TIME_NS):
        raise InvalidDataError(
            f"{where}: cannot write {stream}.t_ns {first_ns} … {last_ns} ns: "
            f"beyond ±{MAX_RUN_TIME_NS} ns (104 days) of the start"
        )


class RecordingWriter(ClosesOnExit, ABC):
    """Streams one recording to a file; a context manager that refuses writes once closed.

    Subclasses implement the ``_write_*``, ``_flush`` and ``_close`` hooks; this class owns
    the closed-state check, block conversion and validation, and the flush policy.

    Parameters
    ----------
    path
        The file to create (replaced if it exists).
    metadata
        Written at the start of the file, so a truncated file keeps it.
    flush_interval_s
        Push buffered data to the OS at least this often, in data time and in wall time, s.
    """

    def __init__(
        self, path: Path, metadata: RecordingMetadata, flush_interval_s: float = 0.5
    ) -> None:
        self.path = Path(path)
        self.metadata = metadata
        self.closed = False
        self._flush_ns = int(flush_interval_s * 1e9)
        self._flush_s = flush_interval_s
        self._flushed_wall = time.monotonic()
        self._flushed_t_ns = 0
        self._latest_t_ns = 0
        self._last: dict[str, NDArray[np.void] | None] = dict.fromkeys(
            ("gauges", "command", "drive"), None
        )
        self._last_event_ns = -(2**63)

    # -- public API -----------------------------------------------------------------------
    def write_gauges(self, block: Block) -> None:
        """Append gauge samples (fields of ``GAUGES_DTYPE``), in time order."""
        arr = self._accept("gauges", block, GAUGES_DTYPE)
        if len(arr):
            self._write_gauges(arr)
            self._after_write(int(arr["t_ns"][-1]))

    def write_command(self, block: Block) -> None:
        """Append drive position commands (fields of ``COMMAND_DTYPE``)."""
        arr = self._accept("command", block, COMMAND_DTYPE)
        if len(arr):
            self._write_command(arr)
            self._after_write(int(arr["t_ns"][-1]))

    def write_drive_state(self, row: Block) -> None:
        """Append one or more drive polls (fields of ``DRIVE_DTYPE``; scalars allowed)."""
        if not isinstance(row, np.ndarray):
            row = {k: np.atleast_1d(v) for k, v in row.items()}
        arr = self._accept("drive", row, DRIVE_DTYPE, strict=False)
        if len(arr):
            self._write_drive(arr)
            self._after_write(int(arr["t_ns"][-1]))

    def write_event(self, t_ns: int, kind: str, text: str = "") -> None:
        """Append one event (start, stop, estop, fault, note, ...) at ``t_ns``."""
        self._check_open()
        if t_ns < self._last_event_ns:
            raise InvalidDataError(
                f"{self.path}: event at {t_ns} ns is earlier than the previous one "
                f"({self._last_event_ns} ns)"
            )
        if not kind:
            raise InvalidDataError(f"{self.path}: an event needs a kind")
        _check_time_range(str(self.path), "events", int(t_ns), int(t_ns))
        self._last_event_ns = int(t_ns)
        self._write_event(int(t_ns), kind, text)
        self._after_write(int(t_ns))

    def flush(self) -> None:
        """Push everything buffered to the operating system."""
        self._check_open()
        self._flush()
        self._flushed_t_ns = self._latest_t_ns
        self._flushed_wall = time.monotonic()

    def close(self) -> None:
        """Write what is buffered and the file's index; idempotent."""
        if self.closed:
            return
        try:
            self._close()
        finally:
            self.closed = True
        log.debug("closed %s", self.path)

    # -- hooks ----------------------------------------------------------------------------
    @abstractmethod
    def _write_gauges(self, block: NDArray[np.void]) -> None: ...

    @abstractmethod
    def _write_command(self, block: NDArray[np.void]) -> None: ...

    @abstractmethod
    def _write_drive(self, block: NDArray[np.void]) -> None: ...

    @abstractmethod
    def _write_event(self, t_ns: int, kind: str, text: str) -> None: ...

    @abstractmethod
    def _flush(self) -> None: ...

    @abstractmethod
    def _close(self) -> None: ...

    # -- shared work ----------------------------------------------------------------------
    def _check_open(self) -> None:
        if self.closed:
            raise WriterClosedError(f"{self.path}: the recording is closed; cannot write")

    def _accept(
        self, stream: str, block: Block, dtype: np.dtype[Any], strict: bool = True
    ) -> NDArray[np.void]:
        self._check_open()
        arr = as_block(block, dtype, f"{self.path}: {stream}")
        if len(arr) == 0:
            return arr
        where = str(self.path)
        check_stream(where, stream, arr, strict)
        _check_time_range(where, stream, int(arr["t_ns"][0]), int(arr["t_ns"][-1]))
        last = self._last[stream]
        if last is not None:
            for name in ("t_ns", "seq") if stream == "gauges" else ("t_ns",):
                before, first = int(last[name][0]), int(arr[name][0])
                if first < before or (strict and first == before):
                    raise InvalidDataError(
                        f"{where}: {stream}.{name} does not increase between blocks "
                        f"({before} then {first})"
                    )
        self._last[stream] = arr[-1:].copy()
        return arr

    def _after_write(self, t_ns: int) -> None:
        self._latest_t_ns = max(self._latest_t_ns, t_ns)
        if (
            self._latest_t_ns - self._flushed_t_ns >= self._flush_ns
            or time.monotonic() - self._flushed_wall >= self._flush_s
        ):
            self.flush()


def open_writer(path: str | Path, metadata: RecordingMetadata, **options: Any) -> RecordingWriter:
    """A streaming writer for ``path``, the format chosen by its suffix (.mcap, .h5)."""
    p = Path(path)
    return writer_for(p)(p, metadata, **options)
