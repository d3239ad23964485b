"""LabVIEW TDMS files (the original stand's), read with npTDMS.

Channels are addressed as ``Group/Channel`` (or ``Channel`` where the name is unique) in
the same mapping as CSV (``recordings.foreign``). Properties used: ``wf_increment``
(the sample interval, so the rate), ``wf_start_offset`` and ``wf_start_time`` (start of
the run, UTC), ``unit_string`` (units, converted to the schema's); NI scaling properties
are applied by npTDMS when the data is read. A truncated TDMS file (LabVIEW killed)
loads with channels of unequal length: they are trimmed to the shortest, and the
recording's ``repairs`` says so.

A damaged file is refused before its data is read: every channel's size against the
file's, its NI scaling and start-time properties are checked on the metadata (npTDMS's
lazy reader), and what npTDMS still raises becomes ``CorruptRecordingError``.
"""

from __future__ import annotations

import errno
import io
import logging
import math
import os
import re
import struct
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, cast

import numpy as np
from nptdms import TdmsFile, scaling
from nptdms.types import DaqMxRawData
from numpy.typing import NDArray

from recordings.errors import (
    CorruptRecordingError,
    ImportMappingError,
    RecordingError,
    one_line,
    shown,
    size_text,
)
from recordings.foreign import FIELDS, MAX_TIME_S, ColumnMap, build_recording, resolve, to_unit
from recordings.recording import Recording
from sim.config import default_config

__all__ = ["read_tdms"]

log = logging.getLogger(__name__)

#: More NI scales than this on one channel is a damaged property, not a sensor chain.
MAX_SCALES = 64
_SCALE_INDEX = re.compile(r"NI_Scale\[(\d+)\]")
#: What npTDMS raises for a damaged file (it parses with struct, numpy and dicts), and
#: RecursionError for NI scales whose input sources form a cycle.
_TDMS_ERRORS = (
    ValueError,
    KeyError,
    IndexError,
    TypeError,
    OSError,
    EOFError,
    struct.error,
    RecursionError,
    OverflowError,
    NotImplementedError,  # a data type npTDMS cannot read
)


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


def _start(name: str, channel: Any, where: str) -> datetime | None:
    value: Any = channel.properties.get("wf_start_time")
    if value is None:
        return None
    if not isinstance(value, np.datetime64 | datetime):
        raise CorruptRecordingError(
            f"{where}: channel {name!r} property wf_start_time is {shown(value)}, not a time stamp"
        )
    stamp = np.datetime64(cast(Any, value), "us").astype(datetime)  # Any: both overloads
    return stamp.replace(tzinfo=UTC) if isinstance(stamp, datetime) else None


def _number(name: str, channel: Any, key: str, default: float | None, where: str) -> float | None:
    """A finite numeric property (``default`` when absent)."""
    value = channel.properties.get(key, default)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise CorruptRecordingError(
            f"{where}: channel {name!r} property {key} is {shown(value)}, not a number"
        )
    number = float(value)
    if not math.isfinite(number) or abs(number) > MAX_TIME_S:
        raise CorruptRecordingError(
            f"{where}: channel {name!r} property {key} = {number:g} is out of range"
        )
    return number


def _check_channel(name: str, channel: Any, tdms: Any, where: str, file_size: int) -> None:
    """What reading the channel would trip on: its size, its NI scaling, its start time."""
    raw_size = getattr(channel.data_type, "size", None) or 1
    if len(channel) * raw_size > file_size:
        raise CorruptRecordingError(
            f"{where}: channel {name!r} claims {len(channel)} values "
            f"({size_text(len(channel) * raw_size)}), more than the file ({size_text(file_size)})"
        )
    props = channel.properties
    scales = [k for k in props if k.startswith("NI_Scale[")]
    count = props.get("NI_Number_Of_Scales", 0)
    indexes = [int(m[1]) for k in scales if (m := _SCALE_INDEX.match(k))]
    if not isinstance(count, int | np.integer) or not 0 <= max([count, *indexes]) <= MAX_SCALES:
        raise CorruptRecordingError(
            f"{where}: channel {name!r} has a broken NI scaling: NI_Number_Of_Scales = "
            f"{shown(count)}, scale indexes up to {max(indexes, default=0)} (at most {MAX_SCALES})"
        )
    try:
        group = tdms[channel.group_name]
        scaling.get_scaling(props, group.properties, tdms.properties)
    except (KeyError, ValueError, TypeError, IndexError) as err:
        detail = f"no property {err}" if isinstance(err, KeyError) else one_line(str(err))
        raise CorruptRecordingError(
            f"{where}: channel {name!r} has a broken NI scaling: {detail}"
        ) from err
    _start(name, channel, where)


class _Bounded(io.BufferedReader):
    """A file whose ``read(n)`` asks for no more than is left in it.

    npTDMS reads a string by the length the file states; a damaged length (4 GB) would
    be allocated before the read finds the file shorter.
    """

    def __init__(self, raw: io.FileIO) -> None:
        super().__init__(raw)
        self._size = os.fstat(raw.fileno()).st_size

    def read(self, size: int | None = -1, /) -> bytes:
        if size is not None and size > 0:
            size = min(size, max(self._size - self.tell(), 0))
        return super().read(size)


class _Collect(logging.Filter):
    """Keeps npTDMS's log records instead of letting its own handler print them."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []

    def filter(self, record: logging.LogRecord) -> bool:
        self.lines.append(record.getMessage())
        return False


@contextmanager
def _nptdms_quiet() -> Iterator[list[str]]:
    """npTDMS prints warnings on stderr itself (names that are not UTF-8, say); collect them.

    Its own handler would print them even under an error, which must stay one line.
    """
    collect = _Collect()
    names = [n for n in list(logging.root.manager.loggerDict) if n.split(".")[0] == "nptdms"]
    loggers = [logging.getLogger(n) for n in names]
    for logger in loggers:
        logger.addFilter(collect)
    try:
        yield collect.lines
    finally:
        for logger in loggers:
            logger.removeFilter(collect)


def _check_numeric(name: str, channel: Any, where: str) -> None:
    """A mapped channel must hold numbers (or DAQmx raw data, which its scaling turns so)."""
    kind = channel.data_type
    nptype = getattr(kind, "nptype", None)
    if kind is DaqMxRawData or (nptype is not None and np.dtype(nptype).kind in "biuf"):
        return
    raise ImportMappingError(
        f"{where}: channel {name!r} holds {getattr(kind, '__name__', kind)} values, not numbers"
    )


def read_tdms(
    path: Path,
    *,
    salvage: bool = False,
    mapping: Mapping[str, ColumnMap] | None = None,
    stand_config: Mapping[str, Any] | None = None,
) -> Recording:
    """Read a TDMS file into a Recording (backend ``import``); see the module docstring.

    ``salvage`` is accepted for the registry: unequal channel lengths are always trimmed
    and reported, as the issue asks. The file's metadata is read and checked first (sizes
    against the file's, scaling, start times); only then the mapped channels' data.
    """
    where = str(path)
    try:
        # Our own file object: npTDMS leaves its own open when its constructor fails.
        with _nptdms_quiet() as warnings, _Bounded(io.FileIO(path)) as f, TdmsFile.open(f) as tdms:
            recording = _read(tdms, path, mapping, stand_config)
    except (FileNotFoundError, RecordingError):
        raise
    except struct.error as err:
        raise CorruptRecordingError(
            f"{where}: not a readable TDMS file: a segment's metadata is cut short ({err})"
        ) from err
    except OSError as err:
        if err.errno != errno.EINVAL:
            raise CorruptRecordingError(
                f"{where}: cannot read the TDMS file: {one_line(str(err))}"
            ) from err
        raise CorruptRecordingError(
            f"{where}: not a readable TDMS file: a segment points outside the file ({err})"
        ) from err
    except _TDMS_ERRORS as err:
        detail = one_line(str(err)) or type(err).__name__
        raise CorruptRecordingError(f"{where}: not a readable TDMS file: {detail}") from err
    for line in warnings:  # shown with -v; a truncated file is reported in its repairs
        log.debug("%s: npTDMS: %s", where, shown(line, 200))
    return recording


def _read(
    tdms: Any,
    path: Path,
    mapping: Mapping[str, ColumnMap] | None,
    stand_config: Mapping[str, Any] | None,
) -> Recording:
    where = str(path)
    channels = _channels(tdms)
    size = path.stat().st_size
    for name, channel in channels.items():
        if "/" in name:  # each channel once, under its full name
            _check_channel(name, channel, tdms, where, size)
    found = resolve(list(channels), mapping or {}, where)
    data: dict[str, NDArray[np.float64]] = {}
    lengths: dict[str, int] = {}
    for field, (name, unit) in found.items():
        channel = channels[name]
        _check_numeric(name, channel, where)
        target = FIELDS[field][0]
        found_unit = unit or channel.properties.get("unit_string") or target
        with np.errstate(over="ignore", invalid="ignore"):  # NI scaling of damaged values
            values = np.asarray(channel[:], dtype=np.float64)  # inf: Recording.check says
        data[field] = to_unit(values, str(found_unit), target, f"{where}: channel {name!r}")
        lengths[name] = len(values)
    repairs: list[str] = []
    n = min(lengths.values())
    if len(set(lengths.values())) > 1:
        detail = ", ".join(f"{k} {v}" for k, v in lengths.items())
        repairs.append(
            f"channels of unequal length ({detail}; a truncated file?): "
            f"trimmed to the shortest, {n} samples"
        )
        data = {k: v[:n] for k, v in data.items()}
    x_name = found["x"][0]
    x_channel = channels[x_name]
    rate_hz: float | None = None
    if "time" in data:
        t_s = data.pop("time")
    else:
        increment = _number(x_name, x_channel, "wf_increment", None, where)
        if increment is None or not increment > 0:
            raise ImportMappingError(
                f"{where}: channel {x_name!r} has no wf_increment and no time channel "
                "is mapped; use --map time=CHANNEL[s]"
            )
        rate_hz = 1.0 / increment
        offset = _number(x_name, x_channel, "wf_start_offset", 0.0, where) or 0.0
        t_s = offset + np.arange(n, dtype=np.float64) * increment
    config = stand_config if stand_config is not None else default_config().to_dict()
    return build_recording(
        path,
        data,
        t_s,
        stand_config=config,
        rate_hz=rate_hz,
        start=_start(x_name, x_channel, where),
        repairs=repairs,
    )
