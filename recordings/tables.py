"""A recording as one table on the gauge clock: CSV and Parquet exports (and Parquet back).

Columns, in this order (units in the CSV names, as the CSV importer reads them; in the
Parquet schema as field metadata ``unit``):

=========  =======  =====================================================
CSV        Parquet  content
=========  =======  =====================================================
t_s        t_ns     gauge time since the start of the run (s / int64 ns)
x_mm       x_mm     drive position, mm
u_mm       u_mm     weight displacement, mm
F_N        F_N      fibre force, N
x_cmd_mm   x_cmd_mm drive command on the gauge clock, mm (empty / null: none)
seq        seq      the front end's sequence counter (unwrapped)
flags      flags    front-end status bits
=========  =======  =====================================================

The rest of the recording travels along so that an export reads back losslessly: in CSV
as preamble lines (``# labstand-metadata: {json}``, one ``# labstand-event: {json}`` per
event, ``# labstand-drive: {json}`` per drive poll), which ``labstand import`` and
``open_recording`` read; in Parquet as key-value metadata (``labstand.metadata``,
``labstand.events``, ``labstand.drive``, ``labstand.units``). pyarrow is imported only
when a Parquet file is written or read.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from recordings.base import EVENTS_DTYPE
from recordings.csvio import DRIVE_TAG, EVENT_TAG, METADATA_TAG, drive_array
from recordings.errors import CorruptRecordingError, MissingChannelError, one_line
from recordings.recording import Recording
from recordings.schema import COMMAND_DTYPE, DRIVE_DTYPE, GAUGES_DTYPE, RecordingMetadata

__all__ = ["read_parquet", "write_table"]

#: Each column's unit (in the CSV names; in the Parquet schema as field metadata).
UNITS = {
    "t_s": "s",
    "t_ns": "ns",
    "x_mm": "mm",
    "u_mm": "mm",
    "F_N": "N",
    "x_cmd_mm": "mm",
    "seq": "",
    "flags": "",
}


def _columns(recording: Recording) -> dict[str, NDArray[Any]]:
    """The gauge-clock columns (without time); x_cmd_mm only when there is a command."""
    g = recording.gauges
    out: dict[str, NDArray[Any]] = {"x_mm": g["x_mm"], "u_mm": g["u_mm"], "F_N": g["force_n"]}
    if len(recording.command):
        out["x_cmd_mm"] = recording.command_on_gauge_clock()
    out["seq"], out["flags"] = g["seq"], g["flags"]
    return out


def _events(recording: Recording) -> list[dict[str, Any]]:
    return [
        {"t_ns": int(t), "kind": str(k), "text": str(x)}
        for t, k, x in recording.events_array.tolist()
    ]


def _drive(recording: Recording) -> list[dict[str, Any]]:
    names = DRIVE_DTYPE.names or ()
    return [dict(zip(names, row, strict=True)) for row in recording.drive.tolist()]


def _write_csv(recording: Recording, path: Path, meta: RecordingMetadata) -> None:
    frame = pd.DataFrame({"t_s": recording.gauges["t_ns"] / 1e9, **_columns(recording)})
    with path.open("w", encoding="utf-8", newline="") as f:
        f.write(METADATA_TAG + meta.to_json() + "\n")
        for event in _events(recording):
            f.write(EVENT_TAG + json.dumps(event, ensure_ascii=False) + "\n")
        for poll in _drive(recording):
            f.write(DRIVE_TAG + json.dumps(poll, separators=(",", ":")) + "\n")
        # pandas writes floats by repr (the shortest text that reads back to the same float)
        frame.to_csv(f, index=False, lineterminator="\n")


def _write_parquet(recording: Recording, path: Path, meta: RecordingMetadata) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = {"t_ns": recording.gauges["t_ns"], **_columns(recording)}
    arrays, fields = [], []
    for name, values in columns.items():
        mask = ~np.isfinite(values) if name == "x_cmd_mm" else None
        array = pa.array(values, mask=mask)
        arrays.append(array)
        fields.append(pa.field(name, array.type, metadata={"unit": UNITS[name]}))
    extra = {
        "labstand.metadata": meta.to_json(),
        "labstand.events": json.dumps(_events(recording), ensure_ascii=False),
        "labstand.drive": json.dumps(_drive(recording), separators=(",", ":")),
        "labstand.units": json.dumps({name: UNITS[name] for name in columns}),
    }
    table = pa.Table.from_arrays(arrays, schema=pa.schema(fields, metadata=extra))
    pq.write_table(table, path, compression="zstd")


def write_table(recording: Recording, path: Path, meta: RecordingMetadata) -> None:
    """Write ``recording`` as CSV or Parquet (by suffix); via a temporary name, no stub."""
    tmp = path.with_name(path.name + ".part")
    try:
        if path.suffix.lower() == ".csv":
            _write_csv(recording, tmp, meta)
        else:
            _write_parquet(recording, tmp, meta)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def read_parquet(path: Path, *, salvage: bool = False) -> Recording:
    """Read a Parquet file written by ``labstand convert`` (``salvage`` is unused)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    where = str(path)
    try:
        table = pq.read_table(path)
    except (pa.ArrowException, OSError) as err:
        if isinstance(err, FileNotFoundError):
            raise
        raise CorruptRecordingError(
            f"{where}: not a readable Parquet file: {one_line(str(err))}"
        ) from None
    extra = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    if "labstand.metadata" not in extra:
        raise MissingChannelError(f"{where}: no labstand.metadata (not a labstand export)")
    meta = RecordingMetadata.from_json(extra["labstand.metadata"], where)
    missing = [
        c for c in ("t_ns", "x_mm", "u_mm", "F_N", "seq", "flags") if c not in table.column_names
    ]
    if missing:
        raise MissingChannelError(f"{where}: no column(s) {', '.join(missing)}")

    gauges, command = _parquet_streams(table, where)
    try:
        events = [
            (int(e["t_ns"]), str(e["kind"]), str(e["text"]))
            for e in json.loads(extra.get("labstand.events", "[]"))
        ]
        polls = json.loads(extra.get("labstand.drive", "[]"))
        if not isinstance(polls, list):
            raise TypeError(f"labstand.drive is {type(polls).__name__}, not a list")
    # RecursionError: JSON nested thousands deep; OverflowError: a time of 1e400
    except (ValueError, KeyError, TypeError, OverflowError, RecursionError) as err:
        message = one_line(repr(err))
        raise CorruptRecordingError(f"{where}: unreadable labstand metadata: {message}") from None
    return Recording(
        path=path,
        metadata=meta,
        gauges=gauges,
        command=command,
        drive=drive_array(polls, where),
        events_array=np.array(events, dtype=EVENTS_DTYPE).reshape(len(events)),
    )


_PARQUET_KINDS = {"t_ns": "iu", "seq": "iu", "flags": "iub", "x_mm": "iuf", "u_mm": "iuf"}
_PARQUET_KINDS |= {"F_N": "iuf", "x_cmd_mm": "iuf"}


def _parquet_streams(table: Any, where: str) -> tuple[NDArray[np.void], NDArray[np.void]]:
    """The gauges and command of a labstand table; every column of the type it must be."""

    def column(name: str) -> NDArray[Any]:
        values = np.asarray(table.column(name).to_numpy(zero_copy_only=False))
        if values.dtype.kind not in _PARQUET_KINDS[name] or values.ndim != 1:
            raise CorruptRecordingError(
                f"{where}: column {name} holds {values.dtype} values, not numbers"
            )
        return values

    gauges = np.empty(table.num_rows, dtype=GAUGES_DTYPE)
    with np.errstate(invalid="raise"):  # NaN into an integer field: refused, not warned
        try:
            gauges["t_ns"], gauges["seq"] = column("t_ns"), column("seq")
            gauges["flags"] = column("flags")
            gauges["x_mm"], gauges["u_mm"] = column("x_mm"), column("u_mm")
            gauges["force_n"] = column("F_N")
        except (FloatingPointError, OverflowError, ValueError, TypeError) as err:
            if isinstance(err, CorruptRecordingError):
                raise
            raise CorruptRecordingError(f"{where}: unusable column: {one_line(str(err))}") from None
    command = np.empty(0, dtype=COMMAND_DTYPE)
    if "x_cmd_mm" in table.column_names:
        x_cmd = column("x_cmd_mm").astype(np.float64)
        present = np.isfinite(x_cmd)
        command = np.empty(int(present.sum()), dtype=COMMAND_DTYPE)
        command["t_ns"], command["x_cmd_mm"] = gauges["t_ns"][present], x_cmd[present]
    return gauges, command
