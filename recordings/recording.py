"""A recording read into memory: what every reader returns, whatever the format."""

from __future__ import annotations

import errno
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from recordings.base import EVENTS_DTYPE, check_stream
from recordings.errors import InvalidDataError
from recordings.formats import reader_for
from recordings.schema import (
    COMMAND_DTYPE,
    DRIVE_DTYPE,
    GAUGES_DTYPE,
    MAX_RUN_TIME_NS,
    RecordingMetadata,
)
from sim.grid import MAX_GRID_FACTOR

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["FRAME_UNITS", "Recording", "open_recording"]

log = logging.getLogger(__name__)

#: Units of the ``frame()`` columns (also in ``df.attrs["units"]``).
FRAME_UNITS = {
    "t_s": "s",
    "x_cmd_mm": "mm",
    "x_mm": "mm",
    "u_mm": "mm",
    "F_N": "N",
    "seq": "",
    "flags": "",
}


def _empty(dtype: np.dtype[Any]) -> NDArray[np.void]:
    return np.empty(0, dtype=dtype)


@dataclass
class Recording:
    """The streams of a recording, checked, in schema units.

    Attributes
    ----------
    path
        The file it was read from.
    metadata
        The recording's metadata.
    gauges, command, drive
        Structured arrays of ``GAUGES_DTYPE``, ``COMMAND_DTYPE``, ``DRIVE_DTYPE``.
    events_array
        Structured array of ``EVENTS_DTYPE`` (strings as objects).
    repairs
        What a salvaging read (or an import) had to do to the data, one line each; empty
        for an intact file.
    """

    path: Path
    metadata: RecordingMetadata
    gauges: NDArray[np.void] = field(default_factory=lambda: _empty(GAUGES_DTYPE))
    command: NDArray[np.void] = field(default_factory=lambda: _empty(COMMAND_DTYPE))
    drive: NDArray[np.void] = field(default_factory=lambda: _empty(DRIVE_DTYPE))
    events_array: NDArray[np.void] = field(default_factory=lambda: _empty(EVENTS_DTYPE))
    repairs: list[str] = field(default_factory=list)

    def check(self) -> None:
        """Raise InvalidDataError for NaNs, times that do not increase, or no samples."""
        where = str(self.path)
        if len(self.gauges) == 0:
            raise InvalidDataError(f"{where}: the gauges stream holds no samples")
        check_stream(where, "gauges", self.gauges)
        check_stream(where, "command", self.command)
        check_stream(where, "drive", self.drive, strict=False)
        check_stream(where, "events", self.events_array, strict=False)
        self._check_times(where)

    def _check_times(self, where: str) -> None:
        """Times within ±MAX_RUN_TIME_NS, and a gauge clock whose grid is bounded.

        Replay and compare put the gauges on a uniform grid at their median step; a time
        that jumps far ahead (a damaged file) would size that grid in terabytes, so the
        span is checked here, before anything is allocated from it.
        """
        for name in ("gauges", "command", "drive", "events_array"):
            t = getattr(self, name)["t_ns"]  # increasing: checked above
            if len(t) and not (int(t[0]) >= -MAX_RUN_TIME_NS and int(t[-1]) <= MAX_RUN_TIME_NS):
                raise InvalidDataError(
                    f"{where}: {name.removesuffix('_array')}.t_ns spans {int(t[0])} … "
                    f"{int(t[-1])} ns, beyond ±{MAX_RUN_TIME_NS} ns (104 days) of the start"
                )
        t = self.gauges["t_ns"]
        if len(t) < 2:
            return
        span_ns = int(t[-1]) - int(t[0])
        step_ns = float(np.median(np.diff(t)))
        if span_ns / step_ns + 1 > MAX_GRID_FACTOR * len(t):
            raise InvalidDataError(
                f"{where}: the gauges span {span_ns / 1e9:.6g} s with {len(t)} samples "
                f"{step_ns / 1e9:.3g} s apart: more than {MAX_GRID_FACTOR - 1} of every "
                f"{MAX_GRID_FACTOR} samples missing (a damaged time?)"
            )

    @property
    def duration_s(self) -> float:
        """Time from the first to the last gauge sample, s."""
        t = self.gauges["t_ns"]
        return float(t[-1] - t[0]) / 1e9 if len(t) else 0.0

    @property
    def lost_samples(self) -> int:
        """Samples missing from the gauges stream according to its sequence counter."""
        seq = self.gauges["seq"]
        return int(seq[-1] - seq[0] + 1 - len(seq)) if len(seq) else 0

    def command_on_gauge_clock(self) -> NDArray[np.float64]:
        """The drive command at the gauge samples' times, mm.

        Taken as it is when both streams share their timestamps; otherwise linearly
        interpolated; NaN outside the command's time span (and everywhere for a
        recording without commands, such as an import).
        """
        g_t, c = self.gauges["t_ns"], self.command
        if len(c) == len(g_t) and np.array_equal(c["t_ns"], g_t):
            return np.asarray(c["x_cmd_mm"], dtype=np.float64)
        if len(c) == 0:
            return np.full(len(g_t), np.nan)
        x_cmd: NDArray[np.float64] = np.interp(
            g_t, c["t_ns"], c["x_cmd_mm"], left=np.nan, right=np.nan
        )
        return x_cmd

    def frame(self) -> pd.DataFrame:
        """The gauge clock as a DataFrame.

        Index ``t_s`` (s since the start of the run); columns ``x_cmd_mm``, ``x_mm``,
        ``u_mm``, ``F_N``, ``seq``, ``flags``; units in ``df.attrs["units"]``, the nominal
        rate in ``df.attrs["rate_hz"]``, the file in ``df.attrs["source"]``.
        """
        import pandas as pd  # ~0.3 s: only for the callers that want a frame

        g = self.gauges
        index = pd.Index(g["t_ns"] / 1e9, name="t_s")
        df = pd.DataFrame(
            {
                "x_cmd_mm": self.command_on_gauge_clock(),
                "x_mm": g["x_mm"],
                "u_mm": g["u_mm"],
                "F_N": g["force_n"],
                "seq": g["seq"],
                "flags": g["flags"],
            },
            index=index,
            copy=False,
        )
        df.attrs["units"] = dict(FRAME_UNITS)
        df.attrs["rate_hz"] = self.metadata.sample_rate_hz
        df.attrs["source"] = str(self.path)
        return df

    def drive_states(self) -> pd.DataFrame:
        """Drive polls, index ``t_s``; units in ``df.attrs["units"]``."""
        import pandas as pd  # ~0.3 s: only for the callers that want a frame

        d = self.drive
        df = pd.DataFrame(
            {name: d[name] for name in DRIVE_DTYPE.names or () if name != "t_ns"},
            index=pd.Index(d["t_ns"] / 1e9, name="t_s"),
        )
        df.attrs["units"] = {"t_s": "s", "position_mm": "mm", "speed_mm_s": "mm/s"}
        return df

    def events(self) -> pd.DataFrame:
        """Events, index ``t_s``; columns ``kind`` and ``text``."""
        import pandas as pd  # ~0.3 s: only for the callers that want a frame

        e = self.events_array
        return pd.DataFrame(
            {"kind": e["kind"].astype(str), "text": e["text"].astype(str)},
            index=pd.Index(e["t_ns"] / 1e9, name="t_s"),
        )

    def channel_counts(self) -> dict[str, tuple[str, float | None, int]]:
        """``stream.field`` -> (unit, nominal rate Hz or None, samples)."""
        sizes = {
            "gauges": len(self.gauges),
            "command": len(self.command),
            "drive": len(self.drive),
            "events": len(self.events_array),
        }
        return {
            name: (info.unit, info.rate_hz, sizes[info.stream])
            for name, info in self.metadata.channels.items()
        }


def open_recording(
    path: str | Path, *, salvage: bool = False, log_repairs: bool = True
) -> Recording:
    """Read a recording (.mcap, .h5/.hdf5, .csv, .parquet) or a foreign run (.csv, .tdms), checked.

    Parameters
    ----------
    path
        The file; its suffix picks the reader (``recordings.formats.FORMATS``).
    salvage
        Read what can be read from a damaged file (a truncated MCAP, an HDF5 file whose
        writer was killed) and list what was done in ``Recording.repairs``, instead of
        raising TruncatedRecordingError.
    log_repairs
        Log each repair as a warning (the default); callers that print
        ``Recording.repairs`` themselves pass False, so the user reads each once.

    Raises
    ------
    RecordingError
        A subclass naming the file and what is wrong (see ``recordings``).
    """
    p = Path(path)
    if p.is_dir():  # before the suffix: a folder named x.mcap is no recording either
        raise IsADirectoryError(errno.EISDIR, "is a folder, not a recording", str(p))
    if not p.exists():  # before the suffix: "no such file" says more than "no reader"
        raise FileNotFoundError(errno.ENOENT, "no such file", str(p))
    recording: Recording = reader_for(p)(p, salvage=salvage)
    recording.check()
    for line in recording.repairs if log_repairs else ():
        log.warning("%s: %s", p, line)
    return recording
