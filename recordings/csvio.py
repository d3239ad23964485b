"""CSV runs: written by ``labstand simulate`` and ``labstand convert``, exported by other tools.

The header ``t_s,x_mm,u_mm,F_N`` (optional ``x_cmd_mm``, ``seq``, ``flags``) is read as it
is; other columns and units through a column mapping (see ``recordings.foreign``). How the
text is split (encoding, preamble, separator, decimal comma) is ``recordings.csvtext``.
A preamble written by ``labstand convert`` (``# labstand-metadata: {...}`` and
``# labstand-event: {...}`` lines) brings the recording's metadata and events back.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from recordings.base import EVENTS_DTYPE, register_format
from recordings.csvtext import CsvOptions, CsvText, split_csv
from recordings.errors import ImportMappingError
from recordings.foreign import FIELDS, ColumnMap, build_recording, resolve, to_unit
from recordings.recording import Recording
from recordings.schema import RecordingMetadata
from sim.config import default_config

__all__ = ["EVENT_TAG", "HEADER", "METADATA_TAG", "CsvOptions", "read_csv", "write_csv"]

HEADER = "t_s,x_mm,u_mm,F_N"
#: Preamble lines ``labstand convert`` writes: the metadata and the events as JSON.
METADATA_TAG = "# labstand-metadata: "
EVENT_TAG = "# labstand-event: "
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
    tmp = path.with_name(path.name + ".part")
    np.savetxt(tmp, table, delimiter=",", header=HEADER, comments="", fmt="%.9g")
    os.replace(tmp, path)


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
        what = "empty" if pd.isna(value) else f"{str(value)!r} is not a finite number"
        hint = ""
        if text.options.decimal == "." and "," in str(value):
            hint = " (comma decimals? use --decimal ,)"
        raise ImportMappingError(f"{text.where}: {text.at(i)}: column {column!r}: {what}{hint}")
    return values


def _stored(text: CsvText) -> tuple[RecordingMetadata | None, list[tuple[int, str, str]], str]:
    """What a labstand preamble says (metadata, events), and the other preamble lines."""
    meta: RecordingMetadata | None = None
    events: list[tuple[int, str, str]] = []
    other: list[str] = []
    for line in text.preamble:
        try:
            if line.startswith(METADATA_TAG):
                meta = RecordingMetadata.from_json(line[len(METADATA_TAG) :], text.where)
            elif line.startswith(EVENT_TAG):
                e = json.loads(line[len(EVENT_TAG) :])
                events.append((int(e["t_ns"]), str(e["kind"]), str(e["text"])))
            else:
                other.append(line.strip())
        except (ValueError, KeyError, TypeError) as err:
            raise ImportMappingError(f"{text.where}: unreadable labstand preamble: {err}") from None
    note = " / ".join(other)
    if len(note) > _NOTE_CHARS:
        note = note[: _NOTE_CHARS - 1] + "…"
    return meta, events, note


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
            f"{where}: no time column (columns: {', '.join(columns)}); "
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
    stored, events, note = _stored(text)
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
        preamble=note,
    )
    if stored is not None:
        recording.metadata = replace(stored, stand_config=config)
        recording.events_array = np.array(events, dtype=EVENTS_DTYPE).reshape(len(events))
    return recording


register_format("CSV", (".csv",), reader=read_csv)
