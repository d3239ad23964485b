"""CSV runs: written by ``labstand simulate`` and ``labstand convert``, exported by other tools.

The header ``t_s,x_mm,u_mm,F_N`` (optional ``x_cmd_mm``, ``seq``, ``flags``) is read as it
is; other columns and units through a column mapping (see ``recordings.foreign``). How the
text is split (encoding, preamble, separator, decimal comma) is ``recordings.csvtext``.
A preamble written by ``labstand convert`` (``# labstand-metadata: {...}`` and
``# labstand-event: {...}`` lines) brings the recording's metadata and events back.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from recordings.atomic import written_whole
from recordings.base import EVENTS_DTYPE
from recordings.csvtext import CsvOptions, CsvText, split_csv
from recordings.errors import (
    CorruptRecordingError,
    ImportMappingError,
    RecordingError,
    listed,
    one_line,
    shown,
)
from recordings.foreign import FIELDS, ColumnMap, build_recording, resolve, to_unit
from recordings.recording import Recording
from recordings.schema import DRIVE_DTYPE, RecordingMetadata
from sim.config import default_config

__all__ = [
    "DRIVE_TAG",
    "EVENT_TAG",
    "HEADER",
    "METADATA_TAG",
    "CsvOptions",
    "drive_array",
    "read_csv",
    "write_csv",
]

HEADER = "t_s,x_mm,u_mm,F_N"
#: Preamble lines ``labstand convert`` writes: the metadata and the events as JSON.
METADATA_TAG = "# labstand-metadata: "
EVENT_TAG = "# labstand-event: "
DRIVE_TAG = "# labstand-drive: "
_NOTE_CHARS = 300  # of a foreign preamble kept in the operator note


def write_csv(
    path: Path,
    t_s: NDArray[np.float64],
    x_mm: NDArray[np.float64],
    u_mm: NDArray[np.float64],
    force_n: NDArray[np.float64],
) -> None:
    """Write the four columns; written to a temporary name first, so a crash leaves no stub."""
    table = np.column_stack([t_s, x_mm, u_mm, force_n])
    with written_whole(path) as tmp:
        np.savetxt(tmp, table, delimiter=",", header=HEADER, comments="", fmt="%.9g")


def _numeric(
    frame: pd.DataFrame, column: str, text: CsvText, allow_empty: bool = False
) -> NDArray[np.float64]:
    raw = frame[column]
    if pd.api.types.is_numeric_dtype(raw.dtype):
        values = raw.to_numpy(dtype=np.float64)
    else:
        strings = raw.astype(str).str.strip()
        if text.options.decimal == ",":
            strings = strings.str.replace(",", ".", regex=False)
        values = pd.to_numeric(strings, errors="coerce").to_numpy(dtype=np.float64)
    bad = ~np.isfinite(values)
    if allow_empty:
        bad &= raw.notna().to_numpy()
    if bad.any():
        i = int(np.argmax(bad))
        value = raw.iloc[i]
        what = "empty" if pd.isna(value) else f"{shown(str(value))} is not a finite number"
        hint = ""
        if text.options.decimal == "." and "," in str(value):
            hint = " (comma decimals? use --decimal ,)"
        raise ImportMappingError(f"{text.where}: {text.at(i)}: column {column!r}: {what}{hint}")
    return values


def drive_array(polls: list[dict[str, Any]], where: str) -> NDArray[np.void]:
    """Drive polls exported as JSON objects (one per poll) as a ``DRIVE_DTYPE`` array."""
    drive = np.empty(len(polls), dtype=DRIVE_DTYPE)
    try:
        for name in DRIVE_DTYPE.names or ():
            drive[name] = [p[name] for p in polls]
    except (KeyError, TypeError, ValueError, OverflowError) as err:  # Overflow: 2**70 ns
        raise CorruptRecordingError(
            f"{where}: unreadable drive polls: {one_line(repr(err))}"
        ) from None
    return drive


@dataclass
class _Stored:
    """What a labstand preamble says, and the other preamble lines as one note."""

    meta: RecordingMetadata | None = None
    events: list[tuple[int, str, str]] = field(default_factory=list)
    drive: list[dict[str, Any]] = field(default_factory=list)
    note: str = ""


def _stored(text: CsvText) -> _Stored:
    out = _Stored()
    other: list[str] = []
    for line in text.preamble:
        try:
            if line.startswith(METADATA_TAG):
                out.meta = RecordingMetadata.from_json(line[len(METADATA_TAG) :], text.where)
            elif line.startswith(EVENT_TAG):
                e = json.loads(line[len(EVENT_TAG) :])
                out.events.append((int(e["t_ns"]), str(e["kind"]), str(e["text"])))
            elif line.startswith(DRIVE_TAG):
                out.drive.append(json.loads(line[len(DRIVE_TAG) :]))
            else:
                other.append(line.strip())
        except RecordingError:  # the metadata's own complaint (newer schema, ...)
            raise
        except (ValueError, KeyError, TypeError, OverflowError) as err:  # 1e400 ns: Overflow
            raise ImportMappingError(f"{text.where}: unreadable labstand preamble: {err}") from None
    note = " / ".join(other)
    out.note = note if len(note) <= _NOTE_CHARS else note[: _NOTE_CHARS - 1] + "…"
    return out


def read_csv(
    path: Path,
    *,
    salvage: bool = False,
    mapping: Mapping[str, ColumnMap] | None = None,
    stand_config: Mapping[str, Any] | None = None,
    options: CsvOptions | None = None,
) -> Recording:
    """Read a CSV run into a Recording (backend ``import``, or the exported recording's).

    Parameters
    ----------
    path
        The file: a preamble, then a header line, then the data (see ``CsvOptions``).
    salvage
        Unused (a CSV has no structure to repair); accepted for the reader registry.
    mapping
        Which column is which quantity, in which unit (``recordings.foreign``); without
        one, the header ``t_s,x_mm,u_mm,F_N`` (and ``x_cmd_mm``) is expected.
    stand_config
        ``StandConfig.to_dict()`` to record in the metadata (default: the one a labstand
        preamble stores, else the paper's stand).
    options
        Encoding, preamble, decimal comma (default: UTF-8, ``#`` comments, ``.``).
    """
    text = split_csv(path, options)
    where = text.where
    frame = text.table()
    columns = list(frame.columns)
    found = resolve(columns, mapping or {}, where)
    if "time" not in found:
        raise ImportMappingError(
            f"{where}: no time column (columns: {listed(list(columns))}); "
            "map it with --map time=COLUMN[s]"
        )
    values: dict[str, NDArray[np.float64]] = {}
    for name, (column, unit) in found.items():
        target = FIELDS[name][0]
        data = _numeric(frame, column, text, allow_empty=name == "x_cmd")
        values[name] = to_unit(data, unit or target, target, f"{where}: column {column!r}")
    t_s = values.pop("time")
    counters = {
        c: _numeric(frame, c, text).astype(np.int64) for c in ("seq", "flags") if c in frame
    }
    kept = _stored(text)
    stored = kept.meta
    config = stand_config
    if config is None:
        config = stored.stand_config if stored else default_config().to_dict()
    recording = build_recording(
        path,
        values,
        t_s,
        stand_config=config,
        rate_hz=stored.sample_rate_hz if stored else None,
        seq=counters.get("seq"),
        flags=counters.get("flags"),
        preamble=kept.note,
    )
    if stored is not None:
        recording.metadata = replace(stored, stand_config=config)
        events = kept.events
        recording.events_array = np.array(events, dtype=EVENTS_DTYPE).reshape(len(events))
        recording.drive = drive_array(kept.drive, where)
    return recording
