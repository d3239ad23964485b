"""CSV runs: written by ``labstand simulate``, exported by other tools.

The header ``t_s,x_mm,u_mm,F_N`` is read as it is; other columns and units through a
column mapping (see ``recordings.foreign``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from recordings.atomic import written_whole
from recordings.base import register_format
from recordings.errors import ImportMappingError
from recordings.foreign import FIELDS, ColumnMap, build_recording, resolve, to_unit
from recordings.recording import Recording
from sim.config import default_config

__all__ = ["HEADER", "read_csv", "write_csv"]

HEADER = "t_s,x_mm,u_mm,F_N"


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


def _numeric(frame: pd.DataFrame, column: str, where: str) -> NDArray[np.float64]:
    raw = frame[column]
    values = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=np.float64)
    bad = ~np.isfinite(values)
    if bad.any():
        i = int(np.argmax(bad))
        raise ImportMappingError(
            f"{where}: column {column!r} line {i + 2}: not a finite number: {raw.iloc[i]!r}"
        )
    return values


def read_csv(
    path: Path,
    *,
    salvage: bool = False,
    mapping: Mapping[str, ColumnMap] | None = None,
    stand_config: Mapping[str, Any] | None = None,
) -> Recording:
    """Read a CSV run into a Recording (backend ``import``).

    Parameters
    ----------
    path
        The file; first line a header; comma separated (or semicolon, or tab).
    salvage
        Unused (a CSV has no structure to repair); accepted for the reader registry.
    mapping
        Which column is which quantity, in which unit (``recordings.foreign``); without
        one, the header ``t_s,x_mm,u_mm,F_N`` (and ``x_cmd_mm``) is expected.
    stand_config
        ``StandConfig.to_dict()`` to record in the metadata (default: the paper's stand).
    """
    where = str(path)
    try:
        with path.open(encoding="utf-8") as f:
            first = f.readline()
        sep = max(",;\t", key=first.count)
        frame = pd.read_csv(path, sep=sep, dtype=str, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as err:
        raise ImportMappingError(f"{where}: not a readable CSV file: {err}") from err
    columns = [str(c).strip() for c in frame.columns]
    frame.columns = pd.Index(columns)
    found = resolve(columns, mapping or {}, where)
    if "time" not in found:
        raise ImportMappingError(
            f"{where}: no time column (columns: {', '.join(columns)}); "
            "map it with --map time=COLUMN[s]"
        )
    values: dict[str, NDArray[np.float64]] = {}
    for field, (column, unit) in found.items():
        target = FIELDS[field][0]
        data = _numeric(frame, column, where)
        values[field] = to_unit(data, unit or target, target, f"{where}: column {column!r}")
    t_s = values.pop("time")
    config = stand_config if stand_config is not None else default_config().to_dict()
    return build_recording(path, values, t_s, stand_config=config)


register_format("CSV", (".csv",), reader=read_csv)
