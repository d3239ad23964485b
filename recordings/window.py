"""A time window of a recording, read without reading the whole file where the format allows.

* MCAP: the ``mcap`` package's seeking reader and the file's chunk index: only the chunks
  whose messages fall in the window (plus the batch that starts before it) are
  decompressed.
* HDF5: the start and end rows are found by bisection on ``t_ns`` (a few chunk reads),
  then only that slice is read.
* Anything else (CSV, TDMS, Parquet), and any file the fast paths cannot read (a truncated
  MCAP without its summary, ...): read whole with ``open_recording``, then cut, so the
  errors are the ordinary reader's.

Times are seconds since the start of the run (the frame's ``t_s``); the window includes
both ends. The window's streams keep their original times (nothing is shifted).
"""

from __future__ import annotations

import bisect
import logging
import mmap
import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from numpy.typing import NDArray

from recordings.base import EVENTS_DTYPE, check_stream
from recordings.errors import CorruptRecordingError, RecordingError
from recordings.mcapcheck import McapLayout
from recordings.recording import Recording, open_recording
from recordings.schema import COMMAND_DTYPE, DRIVE_DTYPE, GAUGES_DTYPE, RecordingMetadata

__all__ = ["Window", "WindowError", "cut", "read_window"]

log = logging.getLogger(__name__)


class WindowError(RecordingError):
    """A window that is not inside the recording, or ends before it starts."""


@dataclass(frozen=True)
class Window:
    """A window ``[start_s, end_s]`` of a recording whose gauges span ``[first_s, last_s]``."""

    recording: Recording
    start_s: float
    end_s: float
    first_s: float
    last_s: float


def _check(where: str, start_s: float | None, end_s: float | None, span: tuple[int, int]) -> None:
    first, last = span[0] / 1e9, span[1] / 1e9
    inside = f"the recording spans {first:.6g} … {last:.6g} s"
    for option, value in (("--start", start_s), ("--end", end_s)):
        if value is not None and not (np.isfinite(value) and first <= value <= last):
            raise WindowError(f"{where}: {option} {value:g} s is outside; {inside}")
    if start_s is not None and end_s is not None and not start_s < end_s:
        raise WindowError(f"{where}: --start {start_s:g} s must be before --end {end_s:g} s")


def _bounds(start_s: float | None, end_s: float | None, span: tuple[int, int]) -> tuple[int, int]:
    lo = span[0] if start_s is None else round(start_s * 1e9)
    hi = span[1] if end_s is None else round(end_s * 1e9)
    return lo, hi


#: The events of an open-ended window reach past the gauges: a run's final note (the
#: simulated stand's last word) comes after its last sample.
_OPEN = (-(2**62), 2**62)


def _event_bounds(start_s: float | None, end_s: float | None, lo: int, hi: int) -> tuple[int, int]:
    return (_OPEN[0] if start_s is None else lo, _OPEN[1] if end_s is None else hi)


def _slice(block: NDArray[np.void], lo: int, hi: int) -> NDArray[np.void]:
    t = block["t_ns"]
    return block[int(np.searchsorted(t, lo, "left")) : int(np.searchsorted(t, hi, "right"))]


def cut(recording: Recording, lo_ns: int, hi_ns: int) -> Recording:
    """The part of ``recording`` with ``lo_ns ≤ t_ns ≤ hi_ns``, in every stream."""
    return Recording(
        path=recording.path,
        metadata=recording.metadata,
        gauges=_slice(recording.gauges, lo_ns, hi_ns),
        command=_slice(recording.command, lo_ns, hi_ns),
        drive=_slice(recording.drive, lo_ns, hi_ns),
        events_array=_slice(recording.events_array, lo_ns, hi_ns),
        repairs=list(recording.repairs),
    )


def _whole(path: Path, start_s: float | None, end_s: float | None) -> Window:
    full = open_recording(path)
    span = (int(full.gauges["t_ns"][0]), int(full.gauges["t_ns"][-1]))
    _check(str(path), start_s, end_s, span)
    lo, hi = _bounds(start_s, end_s, span)
    part = cut(full, lo, hi)
    part.events_array = _slice(full.events_array, *_event_bounds(start_s, end_s, lo, hi))
    return Window(part, lo / 1e9, hi / 1e9, span[0] / 1e9, span[1] / 1e9)


class _FallbackError(Exception):
    """The fast path cannot read this file; read it whole instead."""


def read_window(
    path: str | Path, start_s: float | None = None, end_s: float | None = None
) -> Window:
    """The window ``[start_s, end_s]`` (s since the start of the run; None: to the edge).

    Raises
    ------
    RecordingError
        A bound outside the recording, ``start_s ≥ end_s``, or what ``open_recording``
        raises for the file.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    try:
        if suffix == ".mcap":
            return _mcap_window(p, start_s, end_s)
        if suffix in {".h5", ".hdf5"}:
            return _hdf5_window(p, start_s, end_s)
    except _FallbackError as why:
        log.debug("%s: reading it whole (%s)", p, why)
    return _whole(p, start_s, end_s)


def _finish(
    path: Path,
    meta: RecordingMetadata,
    streams: dict[str, NDArray[np.void]],
    bounds: tuple[int, int],
    span: tuple[int, int],
) -> Window:
    rec = Recording(
        path=path,
        metadata=meta,
        gauges=streams["gauges"],
        command=streams["command"],
        drive=streams["drive"],
        events_array=streams["events"],
    )
    rec.check()
    return Window(rec, bounds[0] / 1e9, bounds[1] / 1e9, span[0] / 1e9, span[1] / 1e9)


def _mcap_window(path: Path, start_s: float | None, end_s: float | None) -> Window:
    from mcap.exceptions import McapError
    from mcap.reader import SeekingReader

    from recordings.mcap_writer import COMMAND_CODEC, DRIVE_CODEC, GAUGE_CODEC, METADATA_NAME
    from recordings.mcapcheck import MAX_CHUNK_BYTES
    from recordings.proto import EVENT, parse

    where = str(path)
    try:
        with path.open("rb") as f:
            layout = _check_mcap_layout(f, where)
            reader = SeekingReader(f, validate_crcs=True, record_size_limit=MAX_CHUNK_BYTES)
            if reader.get_summary() is None:
                raise _FallbackError("no summary section")
            meta_json = next(
                (m.metadata.get("json") for m in reader.iter_metadata() if m.name == METADATA_NAME),
                None,
            )
            if meta_json is None:
                raise _FallbackError("no labstand metadata record")
            meta = RecordingMetadata.from_json(meta_json, where)
            t0 = meta.start_time_ns

            def batches(topic: str, lo: int, hi: int) -> list[bytes]:
                found = reader.iter_messages(topics=[topic], starting_at=t0 + lo, ending_at=t0 + hi)
                return [m.data for _, _, m in found]

            def edge(reverse: bool) -> NDArray[np.void]:
                first = next(reader.iter_messages(topics=["/gauges"], reverse=reverse), None)
                return GAUGE_CODEC.decode_many([first[2].data] if first else [], where)

            head, tail = edge(reverse=False), edge(reverse=True)
            if not len(head):
                raise _FallbackError("no gauge samples")
            span = (int(head["t_ns"][0]), int(tail["t_ns"][-1]))
            _check(where, start_s, end_s, span)
            lo, hi = _bounds(start_s, end_s, span)
            channels = _check_window_chunks(f, layout, t0 + lo, t0 + hi, where)
            _same_channels(channels, reader.get_summary(), where)
            streams: dict[str, Any] = {}
            for name, topic, codec in (
                ("gauges", "/gauges", GAUGE_CODEC),
                ("command", "/command", COMMAND_CODEC),
            ):
                # the batch that starts before the window holds its first samples
                before = next(
                    reader.iter_messages(topics=[topic], ending_before=t0 + lo, reverse=True), None
                )
                data = ([before[2].data] if before else []) + batches(topic, lo, hi)
                decoded = codec.decode_many(data, where)
                check_stream(where, name, decoded)  # all it read, not only the window's part
                streams[name] = _slice(decoded, lo, hi)
            drive = DRIVE_CODEC.decode_fast(batches("/drive", lo, hi))
            if drive is None:
                raise _FallbackError("drive polls not in the fixed layout")
            drive_rows = _as(drive, DRIVE_DTYPE)
            check_stream(where, "drive", drive_rows, strict=False)
            streams["drive"] = _slice(drive_rows, lo, hi)
            e_lo, e_hi = _event_bounds(start_s, end_s, lo, hi)
            e_lo, e_hi = max(e_lo, -t0), min(e_hi, 2**63 - 1 - t0)
            events = [parse(EVENT, d, where) for d in batches("/events", e_lo, e_hi)]
            streams["events"] = np.array(
                [(e.t_ns, e.kind, e.text) for e in events], dtype=EVENTS_DTYPE
            ).reshape(len(events))
    except RecordingError:
        raise
    # what the seeking reader may still raise inside a chunk: the walk says what is wrong
    except (McapError, EOFError, ValueError, KeyError, struct.error, OverflowError) as err:
        raise _FallbackError(f"{type(err).__name__}: {err}") from err
    return _finish(path, meta, streams, (lo, hi), span)


def _check_mcap_layout(f: BinaryIO, where: str) -> McapLayout:
    """The MCAP layout check of every read path; a file it finds cut goes to the walk."""
    from recordings.mcapcheck import check_layout

    if os.fstat(f.fileno()).st_size < 16:
        raise _FallbackError("shorter than an MCAP header")
    with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
        layout = check_layout(data, where)  # type: ignore[arg-type]  # mmap reads as bytes
        if not layout.intact:
            raise _FallbackError(layout.problem)
    return layout


def _same_channels(data: dict[int, Any], summary: Any, where: str) -> None:
    """The channels the data defines must be the summary's (the seeking reader's)."""
    for cid, channel in data.items():
        known = summary.channels.get(cid) if summary is not None else None
        mine = (channel.topic, channel.schema_id, channel.message_encoding)
        if known is None or (known.topic, known.schema_id, known.message_encoding) != mine:
            raise CorruptRecordingError(
                f"{where}: channel {cid} ({channel.topic!r}) differs between the data and "
                f"the summary; `labstand recover {where} -o FIXED.mcap` rebuilds the summary"
            )


def _check_window_chunks(
    f: BinaryIO, layout: McapLayout, lo: int, hi: int, where: str
) -> dict[int, Any]:
    """The whole read's chunk checks on the chunks the window reads (and the edges').

    Those overlapping ``lo … hi`` (log times), the one before them (its batch starts
    before the window), and the first and last (the span's edges).
    """
    from recordings.mcap_reader import check_chunks

    chunks = layout.chunks
    if not chunks:
        return {}
    hit = [i for i, c in enumerate(chunks) if c.end_ns >= lo and c.start_ns <= hi]
    picked = set(hit) | {0, len(chunks) - 1} | ({hit[0] - 1} if hit and hit[0] else set())
    wanted = []
    for i in sorted(picked):
        f.seek(chunks[i].offset)  # inside the file: the layout check saw the whole record
        wanted.append((chunks[i].offset, f.read(chunks[i].length)))
    return check_chunks(wanted, where)


def _as(fields: Any, dtype: np.dtype[Any]) -> NDArray[np.void]:
    names = dtype.names or ()
    out = np.empty(len(fields[names[0]]), dtype=dtype)
    for name in names:
        out[name] = fields[name]
    return out


def _hdf5_window(path: Path, start_s: float | None, end_s: float | None) -> Window:
    from recordings.hdf5io import checked_hdf5

    where = str(path)
    with checked_hdf5(path) as h5:  # the same checks as a whole read: links, shapes, sizes
        ds = h5.datasets
        g = ds["gauges"]
        if len(g) == 0:
            raise _FallbackError("no gauge samples")
        span = (int(g[0]["t_ns"]), int(g[-1]["t_ns"]))
        _check(where, start_s, end_s, span)
        lo, hi = _bounds(start_s, end_s, span)
        streams: dict[str, Any] = {}
        for name, dtype in (
            ("gauges", GAUGES_DTYPE),
            ("command", COMMAND_DTYPE),
            ("drive", DRIVE_DTYPE),
        ):
            rows = range(len(ds[name]))

            def t_at(i: int, d: Any = ds[name]) -> int:
                return int(d[i]["t_ns"])

            a = bisect.bisect_left(rows, lo, key=t_at)
            b = bisect.bisect_right(rows, hi, key=t_at)
            part = np.asarray(ds[name][a:b]) if b > a else np.empty(0, ds[name].dtype)
            streams[name] = _as(part, dtype)
        e = ds["events"][...]
        events = np.empty(len(e), dtype=EVENTS_DTYPE)
        events["t_ns"] = e["t_ns"]
        for key in ("kind", "text"):
            events[key] = [v.decode() if isinstance(v, bytes) else str(v) for v in e[key]]
        streams["events"] = _slice(events, *_event_bounds(start_s, end_s, lo, hi))
    return _finish(path, h5.metadata, streams, (lo, hi), span)
