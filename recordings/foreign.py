"""Mapping a foreign file's columns (CSV, TDMS) onto the schema, with unit conversion.

A mapping says which column holds which quantity: ``FIELD=NAME`` or ``FIELD=NAME[UNIT]``.
FIELD is one of ``time``, ``x``, ``u``, ``F``, ``x_cmd`` (aliases: ``t``, ``force``). NAME
is matched against the file's column names, first as written (so a column literally
called ``Time[ms]`` matches ``time=Time[ms]`` and its bracket gives the unit), then with
the ``[UNIT]`` part taken off. Without a unit in the mapping, the unit comes from the
column name's brackets, the file's own unit property (TDMS ``unit_string``) or, failing
those, the schema's (s, mm, N).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from recordings.errors import ImportMappingError, listed
from recordings.recording import Recording
from recordings.schema import COMMAND_DTYPE, GAUGES_DTYPE, Backend, make_metadata

__all__ = ["FIELDS", "MAX_TIME_S", "ColumnMap", "build_recording", "parse_mapping", "to_unit"]

#: Times beyond ±292 years do not fit the schema's int64 nanoseconds.
MAX_TIME_S = 9.2e9

#: field -> (schema unit, default column names tried in order)
FIELDS: dict[str, tuple[str, tuple[str, ...]]] = {
    "time": ("s", ("t_s", "time_s", "time", "t")),
    "x": ("mm", ("x_mm", "x")),
    "u": ("mm", ("u_mm", "u")),
    "F": ("N", ("F_N", "force_n", "F", "force")),
    "x_cmd": ("mm", ("x_cmd_mm", "x_cmd")),
}
_ALIASES = {"t": "time", "force": "F", "f": "F", "xcmd": "x_cmd"}
REQUIRED = ("x", "u", "F")
_SCALE = {
    "s": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "ns": 1e-9, "min": 60.0},
    "mm": {"mm": 1.0, "m": 1e3, "cm": 10.0, "um": 1e-3, "µm": 1e-3, "in": 25.4},
    "N": {"N": 1.0, "kN": 1e3, "mN": 1e-3, "daN": 10.0, "lbf": 4.4482216152605},
}
_UNIT_IN_NAME = re.compile(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\])]*)[\])]\s*$")


@dataclass(frozen=True)
class ColumnMap:
    """One ``FIELD=NAME[UNIT]`` mapping entry."""

    field: str
    name: str
    unit: str | None


def parse_mapping(items: Sequence[str]) -> dict[str, ColumnMap]:
    """Parse ``--map`` values; raise ImportMappingError for a malformed or unknown one."""
    out: dict[str, ColumnMap] = {}
    for item in items:
        key, sep, value = item.partition("=")
        field = _ALIASES.get(key.strip().lower(), key.strip())
        if not sep or not value.strip():
            raise ImportMappingError(f"--map {item!r}: expected FIELD=COLUMN or FIELD=COLUMN[UNIT]")
        if field not in FIELDS:
            known = ", ".join(FIELDS)
            raise ImportMappingError(f"--map {item!r}: unknown field {key!r}; known: {known}")
        match = _UNIT_IN_NAME.match(value.strip())
        unit = match["unit"].strip() if match else None
        if unit is not None:
            to_unit(1.0, unit, FIELDS[field][0], f"--map {item!r}")
        out[field] = ColumnMap(field, value.strip(), unit)
    return out


def to_unit(values: Any, unit: str, target: str, where: str) -> Any:
    """``values`` in ``unit`` converted to ``target`` (s, mm or N)."""
    table = _SCALE[target]
    key = unit.strip()
    scale = table.get(key)
    if scale is None:
        scale = {k.lower(): v for k, v in table.items()}.get(key.lower())
    if scale is None:
        known = ", ".join(table)
        raise ImportMappingError(f"{where}: unit {unit!r} is not one of {known}")
    with np.errstate(over="ignore", invalid="ignore"):
        out = values * scale
    # Only what the conversion overflowed; a NaN read from the file is Recording.check's.
    overflowed = ~np.isfinite(out) & np.isfinite(values) if isinstance(out, np.ndarray) else None
    if overflowed is not None and overflowed.any():
        i = int(np.argmax(overflowed))
        raise ImportMappingError(
            f"{where}: value {values[i]:g} {unit} at sample {i} is too large to convert to {target}"
        )
    return out


def resolve(
    columns: Sequence[str], mapping: Mapping[str, ColumnMap], where: str
) -> dict[str, tuple[str, str | None]]:
    """field -> (column name, unit or None) for every field found; required ones or error."""
    found: dict[str, tuple[str, str | None]] = {}
    for field, (_, defaults) in FIELDS.items():
        entry = mapping.get(field)
        if entry is not None:
            if entry.name in columns:
                name_unit = _UNIT_IN_NAME.match(entry.name)
                found[field] = (entry.name, name_unit["unit"] if name_unit else None)
                continue
            bare = _UNIT_IN_NAME.match(entry.name)
            if bare and bare["name"] in columns:
                found[field] = (bare["name"], entry.unit)
                continue
            raise ImportMappingError(
                f"{where}: no column {entry.name!r} for {field}; columns: {listed(list(columns))}"
            )
        for name in columns:
            base = _UNIT_IN_NAME.match(name)
            bare_name = base["name"] if base else name
            if name in defaults or bare_name in defaults:
                found[field] = (name, base["unit"] if base else None)
                break
    missing = [f for f in REQUIRED if f not in found]
    if missing:
        raise ImportMappingError(
            f"{where}: no column for {', '.join(missing)} (columns: {listed(list(columns))}); "
            "map them with --map FIELD=COLUMN[UNIT]"
        )
    return found


def build_recording(
    path: Path,
    values_mm_n: Mapping[str, NDArray[np.float64]],
    t_s: NDArray[np.float64],
    *,
    stand_config: Mapping[str, Any],
    rate_hz: float | None = None,
    start: datetime | None = None,
    repairs: list[str] | None = None,
    seq: NDArray[np.int64] | None = None,
    flags: NDArray[np.int64] | None = None,
    preamble: str = "",
) -> Recording:
    """A Recording from imported columns in schema units (x, u, F and maybe x_cmd).

    The sequence counter is rebuilt from time: ``seq = round((t − t₀)·rate)``, so a gap
    in the time column shows as lost samples (unless the file has its own ``seq``). The
    rate is the median sample spacing's unless given. ``x_cmd`` may be NaN where there
    was no command. ``preamble`` (the file's own header text) goes into the operator note.
    """
    where = str(path)
    n = len(t_s)
    if n < 2:
        raise ImportMappingError(f"{where}: needs at least 2 samples, got {n}")
    outside = ~(np.abs(t_s) < MAX_TIME_S)
    if outside.any():
        i = int(np.argmax(outside))
        raise ImportMappingError(
            f"{where}: time {t_s[i]:g} s at sample {i} is beyond ±{MAX_TIME_S:g} s "
            "(the schema's nanosecond clock)"
        )
    if rate_hz is None:
        spacing = float(np.median(np.diff(t_s)))
        if not (math.isfinite(spacing) and spacing > 0):
            raise ImportMappingError(f"{where}: the time column does not increase")
        rate_hz = 1.0 / spacing
    t_ns = np.round(t_s * 1e9).astype(np.int64)
    gauges = np.empty(n, dtype=GAUGES_DTYPE)
    gauges["t_ns"] = t_ns
    gauges["seq"] = seq if seq is not None else np.round((t_s - t_s[0]) * rate_hz)
    gauges["x_mm"] = values_mm_n["x"]
    gauges["u_mm"] = values_mm_n["u"]
    gauges["force_n"] = values_mm_n["F"]
    gauges["flags"] = flags if flags is not None else 0
    command = np.empty(0, dtype=COMMAND_DTYPE)
    if "x_cmd" in values_mm_n:
        x_cmd = values_mm_n["x_cmd"]
        present = np.isfinite(x_cmd)
        command = np.empty(int(present.sum()), dtype=COMMAND_DTYPE)
        command["t_ns"] = t_ns[present]
        command["x_cmd_mm"] = x_cmd[present]
    if start is None:
        start = datetime.fromtimestamp(path.stat().st_mtime, tz=UTC)
        start_note = "start time taken from the file's modification time"
    else:
        start_note = "start time from the file"
    metadata = make_metadata(
        stand_config,
        Backend.IMPORT,
        sample_rate_hz=float(rate_hz),
        operator_note=f"imported from {path.name}; {start_note}"
        + (f"; the file's preamble: {preamble}" if preamble else ""),
        source=path.name,
        start=start,
    )
    return Recording(
        path=path, metadata=metadata, gauges=gauges, command=command, repairs=repairs or []
    )
