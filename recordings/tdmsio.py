"""LabVIEW TDMS files (the original stand's), read with npTDMS.

Channels are addressed as ``Group/Channel`` (or ``Channel`` where the name is unique) in
the same mapping as CSV (``recordings.foreign``). Properties used: ``wf_increment``
(the sample interval, so the rate), ``wf_start_offset`` and ``wf_start_time`` (start of
the run, UTC), ``unit_string`` (units, converted to the schema's); NI scaling properties
are applied by npTDMS when the data is read. A truncated TDMS file (LabVIEW killed)
loads with channels of unequal length: they are trimmed to the shortest, and the
recording's ``repairs`` says so.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from nptdms import TdmsFile
from numpy.typing import NDArray

from recordings.base import register_format
from recordings.errors import CorruptRecordingError, ImportMappingError
from recordings.foreign import FIELDS, ColumnMap, build_recording, resolve, to_unit
from recordings.recording import Recording
from sim.config import default_config

__all__ = ["read_tdms"]

log = logging.getLogger(__name__)


def _channels(tdms: Any) -> dict[str, Any]:
    """Every channel under ``Group/Channel``, and under ``Channel`` where unique."""
    full: dict[str, Any] = {}
    bare: dict[str, list[Any]] = {}
    for group in tdms.groups():
        for channel in group.channels():
            full[f"{group.name}/{channel.name}"] = channel
            bare.setdefault(channel.name, []).append(channel)
    names = dict(full)
    for name, found in bare.items():
        if len(found) == 1 and name not in names:
            names[name] = found[0]
    return names


def _start(channel: Any) -> datetime | None:
    value = channel.properties.get("wf_start_time")
    if value is None:
        return None
    stamp = np.datetime64(value, "us").astype(datetime)
    return stamp.replace(tzinfo=UTC) if isinstance(stamp, datetime) else None


def read_tdms(
    path: Path,
    *,
    salvage: bool = False,
    mapping: Mapping[str, ColumnMap] | None = None,
    stand_config: Mapping[str, Any] | None = None,
) -> Recording:
    """Read a TDMS file into a Recording (backend ``import``); see the module docstring.

    ``salvage`` is accepted for the registry: unequal channel lengths are always trimmed
    and reported, as the issue asks.
    """
    where = str(path)
    try:
        tdms = TdmsFile.read(path)
    except (ValueError, KeyError, OSError, EOFError) as err:
        if isinstance(err, FileNotFoundError):
            raise
        raise CorruptRecordingError(f"{where}: not a readable TDMS file: {err}") from err
    channels = _channels(tdms)
    found = resolve(list(channels), mapping or {}, where)
    data: dict[str, NDArray[np.float64]] = {}
    lengths: dict[str, int] = {}
    for field, (name, unit) in found.items():
        channel = channels[name]
        target = FIELDS[field][0]
        found_unit = unit or channel.properties.get("unit_string") or target
        values = np.asarray(channel[:], dtype=np.float64)
        data[field] = to_unit(values, str(found_unit), target, f"{where}: channel {name!r}")
        lengths[name] = len(values)
    repairs: list[str] = []
    size = min(lengths.values())
    if len(set(lengths.values())) > 1:
        detail = ", ".join(f"{k} {v}" for k, v in lengths.items())
        repairs.append(
            f"channels of unequal length ({detail}; a truncated file?): "
            f"trimmed to the shortest, {size} samples"
        )
        data = {k: v[:size] for k, v in data.items()}
    x_channel = channels[found["x"][0]]
    rate_hz: float | None = None
    if "time" in data:
        t_s = data.pop("time")
    else:
        increment = x_channel.properties.get("wf_increment")
        if increment is None or not float(increment) > 0:
            raise ImportMappingError(
                f"{where}: channel {found['x'][0]!r} has no wf_increment and no time channel "
                "is mapped; use --map time=CHANNEL[s]"
            )
        rate_hz = 1.0 / float(increment)
        offset = float(x_channel.properties.get("wf_start_offset", 0.0))
        t_s = offset + np.arange(size, dtype=np.float64) * float(increment)
    config = stand_config if stand_config is not None else default_config().to_dict()
    return build_recording(
        path,
        data,
        t_s,
        stand_config=config,
        rate_hz=rate_hz,
        start=_start(x_channel),
        repairs=repairs,
    )


register_format("TDMS", (".tdms",), reader=read_tdms)
