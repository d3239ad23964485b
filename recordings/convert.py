"""Writing a read recording out again (convert, import, recover), and its summary."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from recordings.atomic import written_whole
from recordings.base import EVENTS_DTYPE, open_writer
from recordings.formats import format_for
from recordings.recording import Recording
from recordings.schema import COMMAND_DTYPE, DRIVE_DTYPE, RecordingMetadata

__all__ = ["summary", "with_changes", "write_recording", "write_streams"]

log = logging.getLogger(__name__)

#: Samples per write call when copying (1 s at 2 kHz).
BLOCK = 2000


def write_streams(
    path: Path,
    metadata: RecordingMetadata,
    gauges: NDArray[np.void],
    command: NDArray[np.void] | None = None,
    drive: NDArray[np.void] | None = None,
    events: list[tuple[int, str, str]] | None = None,
) -> None:
    """Write whole streams in time order, block by block, as a live run would.

    Writes to a temporary name and renames at the end, so a failed write leaves no stub;
    an error names ``path`` (``recordings.atomic``).
    """
    command = command if command is not None else np.empty(0, COMMAND_DTYPE)
    drive = drive if drive is not None else np.empty(0, DRIVE_DTYPE)
    pending_events = sorted(events or [], key=lambda e: e[0])
    with written_whole(path, path.suffix) as tmp, open_writer(tmp, metadata) as writer:
        g_at = c_at = d_at = e_at = 0
        while g_at < len(gauges) or c_at < len(command):
            # the next second of the clock, in whichever stream is behind
            t_end = _next_end(gauges, g_at, command, c_at)
            g_to = int(np.searchsorted(gauges["t_ns"], t_end, side="right"))
            c_to = int(np.searchsorted(command["t_ns"], t_end, side="right"))
            d_to = int(np.searchsorted(drive["t_ns"], t_end, side="right"))
            if g_to > g_at:
                writer.write_gauges(gauges[g_at:g_to])
            if c_to > c_at:
                writer.write_command(command[c_at:c_to])
            if d_to > d_at:
                writer.write_drive_state(drive[d_at:d_to])
            while e_at < len(pending_events) and pending_events[e_at][0] <= t_end:
                writer.write_event(*pending_events[e_at])
                e_at += 1
            g_at, c_at, d_at = g_to, c_to, d_to
        if d_at < len(drive):
            writer.write_drive_state(drive[d_at:])
        for event in pending_events[e_at:]:
            writer.write_event(*event)


def _next_end(gauges: NDArray[np.void], g_at: int, command: NDArray[np.void], c_at: int) -> int:
    starts = []
    if g_at < len(gauges):
        starts.append(int(gauges["t_ns"][min(g_at + BLOCK, len(gauges)) - 1]))
    if c_at < len(command):
        starts.append(int(command["t_ns"][min(c_at + BLOCK, len(command)) - 1]))
    return min(starts)


def write_recording(
    recording: Recording, path: Path, metadata: RecordingMetadata | None = None
) -> None:
    """Write a recording (or a salvaged or imported one) to ``path`` (format by suffix).

    ``.mcap``/``.h5`` stream through a writer; ``.csv``/``.parquet`` are written as one
    table on the gauge clock (``recordings.tables``).
    """
    meta = metadata or recording.metadata
    events = [(int(t), str(k), str(x)) for t, k, x in recording.events_array.tolist()]
    for line in recording.repairs:
        t_ns = int(recording.gauges["t_ns"][-1]) if len(recording.gauges) else 0
        events.append((t_ns, "repair", line))
    fmt = format_for(path, "write", "table")  # refused before anything is written
    if fmt.table_writer:  # pandas (and pyarrow) only when a table is written
        array = np.array(events, dtype=EVENTS_DTYPE).reshape(len(events))
        table = dataclasses.replace(recording, events_array=array, repairs=[])
        fmt.load("table")(table, path, meta)
    else:
        write_streams(path, meta, recording.gauges, recording.command, recording.drive, events)
    log.info("wrote %s (%d samples)", path, len(recording.gauges))


def summary(recording: Recording) -> dict[str, Any]:
    """What ``labstand info --json`` prints."""
    meta = recording.metadata
    gauges = recording.gauges
    channels = {
        name: {"unit": unit, "rate_hz": rate, "samples": samples}
        for name, (unit, rate, samples) in recording.channel_counts().items()
    }
    seq = gauges["seq"]
    gaps = np.diff(seq) - 1
    measured_rate = None
    if len(gauges) > 1:
        measured_rate = float((len(gauges) - 1) / (gauges["t_ns"][-1] - gauges["t_ns"][0]) * 1e9)
    meta_dict = meta.to_dict()
    meta_dict.pop("channels")
    return {
        "path": str(recording.path),
        "duration_s": recording.duration_s,
        "start_time_utc": meta.start_time_utc,
        "samples": len(gauges),
        "lost_samples": recording.lost_samples,
        "gaps": int(np.count_nonzero(gaps > 0)),
        "measured_rate_hz": measured_rate,
        "channels": channels,
        "drive_states": len(recording.drive),
        "events": len(recording.events_array),
        "event_list": [
            {"t_s": int(t) / 1e9, "kind": str(k), "text": str(x)}
            for t, k, x in recording.events_array.tolist()
        ],
        "repairs": list(recording.repairs),
        "metadata": meta_dict,
    }


def with_changes(metadata: RecordingMetadata, **changes: Any) -> RecordingMetadata:
    """A copy of ``metadata`` with some fields replaced."""
    return dataclasses.replace(metadata, **changes)
