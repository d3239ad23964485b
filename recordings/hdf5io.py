"""Recordings as HDF5 (h5py): one group per stream, one resizable dataset per field.

Layout (docs/recording-format.md)::

    /          attrs: schema_version, metadata_json, start_time_utc, backend, ...
    /gauges    compound (seq, t_ns, x_mm, u_mm, force_n, flags); chunked, shuffle + gzip
    /command   compound (t_ns, x_cmd_mm); as /gauges
    /drive     compound (t_ns, position_mm, speed_mm_s, status_word, trip_code, enabled)
    /events    compound (t_ns, kind, text); strings UTF-8 of variable length

Each dataset is one stream (its fields share one clock) with attributes ``rate_hz``
(the 2 kHz streams), ``units`` (JSON: field -> unit) and ``unit_<field>`` per field.

The gauges and command streams are appended one whole chunk (0.5 s) at a time and the
file is flushed after each, because a compressed chunk rewritten while it grows leaves
dead space behind; only ``close`` writes the last partial chunk. The file is created with
``libver=('v110', 'latest')`` (readable by the HDF5 1.10 tools of Debian) and switched to
SWMR mode, so a live reader can open it and a killed writer leaves a consistent file,
which ``open_recording(..., salvage=True)`` opens in SWMR-read mode.

Reading checks the file before h5py touches what could hang it or allocate what a
damaged header claims (``recordings.hdf5check``), and turns what h5py still raises into
``CorruptRecordingError``.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from recordings.base import EVENTS_DTYPE, RecordingWriter
from recordings.errors import (
    CorruptRecordingError,
    MissingChannelError,
    RecordingError,
    SchemaVersionError,
    TruncatedRecordingError,
    one_line,
)
from recordings.hdf5check import check_dataset, check_global_heaps, int_attr, text_attr
from recordings.recording import Recording
from recordings.schema import (
    COMMAND_DTYPE,
    DRIVE_DTYPE,
    GAUGES_DTYPE,
    SCHEMA_VERSION,
    UNITS,
    RecordingMetadata,
    concat_blocks,
)

__all__ = ["CheckedHdf5", "Hdf5RecordingWriter", "checked_hdf5", "read_hdf5"]

log = logging.getLogger(__name__)

_STR = h5py.string_dtype("utf-8")
_LOW_RATE_CHUNK = 256
GZIP_LEVEL = 1  # level 4 saves 3 % of the size and costs 35 % more time (benchmark)


class _Stream:
    """The dataset of one stream and the rows not yet written."""

    def __init__(
        self,
        h5: h5py.File,
        name: str,
        dtype: np.dtype[Any],
        chunk: int,
        rate_hz: float | None,
        compress: bool,
    ) -> None:
        self.chunk = chunk
        self.size = 0
        self.pending: list[NDArray[np.void]] = []
        self.pending_rows = 0
        compressed = compress and rate_hz is not None
        self.dataset = h5.create_dataset(
            name,
            shape=(0,),
            maxshape=(None,),
            chunks=(chunk,),
            dtype=_file_dtype(dtype),
            compression="gzip" if compressed else None,
            compression_opts=GZIP_LEVEL if compressed else None,
            shuffle=compressed,
        )
        units = {f: UNITS.get(f, "") for f in dtype.names or ()}
        self.dataset.attrs["units"] = json.dumps(units)
        for field, unit in units.items():
            self.dataset.attrs[f"unit_{field}"] = unit
        if rate_hz is not None:
            self.dataset.attrs["rate_hz"] = rate_hz

    def add(self, block: NDArray[np.void]) -> None:
        self.pending.append(block)
        self.pending_rows += len(block)

    def write(self, whole_chunks_only: bool) -> bool:
        """Append pending rows (whole chunks only, if asked); True if anything was written."""
        rows = self.pending_rows
        if whole_chunks_only:
            rows = rows // self.chunk * self.chunk
        if not rows:
            return False
        data = concat_blocks(self.pending)
        new_size = self.size + rows
        self.dataset.resize((new_size,))
        self.dataset[self.size : new_size] = data[:rows]
        self.size = new_size
        rest = data[rows:]
        self.pending = [rest] if len(rest) else []
        self.pending_rows = len(rest)
        return True


def _file_dtype(dtype: np.dtype[Any]) -> np.dtype[Any]:
    """Object (string) fields become HDF5 variable-length UTF-8 strings."""
    fields = [(n, _STR if dtype[n] == np.dtype(object) else dtype[n]) for n in dtype.names or ()]
    return np.dtype(fields)


class Hdf5RecordingWriter(RecordingWriter):
    """Streams a recording into an HDF5 file (see the module docstring).

    Parameters
    ----------
    path, metadata, flush_interval_s
        See ``RecordingWriter``.
    chunk_s
        Duration of one gauges/command chunk, s; whole chunks are appended and flushed.
    compress
        Shuffle + gzip the 2 kHz streams (default); False reads 3× faster, 3× larger.
    """

    def __init__(
        self,
        path: Path,
        metadata: RecordingMetadata,
        flush_interval_s: float = 0.5,
        chunk_s: float = 0.5,
        compress: bool = True,
    ) -> None:
        super().__init__(path, metadata, flush_interval_s)
        self._compress = compress
        self._h5 = h5py.File(self.path, "w", libver=("v110", "latest"))
        try:
            self._streams = self._layout(metadata, max(round(chunk_s * metadata.sample_rate_hz), 1))
            self._h5.swmr_mode = True
        except BaseException:
            self._h5.close()
            raise
        self._h5.flush()

    def _layout(self, metadata: RecordingMetadata, chunk: int) -> dict[str, _Stream]:
        attrs = self._h5.attrs
        attrs["schema_version"] = metadata.schema_version
        attrs["metadata_json"] = metadata.to_json()
        attrs["start_time_utc"] = metadata.start_time_utc
        attrs["backend"] = str(metadata.backend)
        attrs["software_version"] = metadata.software_version
        attrs["host"] = metadata.host
        attrs["sample_rate_hz"] = metadata.sample_rate_hz
        attrs["operator_note"] = metadata.operator_note
        rate = metadata.sample_rate_hz
        return {
            name: _Stream(self._h5, name, dtype, size, stream_rate, self._compress)
            for name, dtype, size, stream_rate in (
                ("gauges", GAUGES_DTYPE, chunk, rate),
                ("command", COMMAND_DTYPE, chunk, rate),
                ("drive", DRIVE_DTYPE, _LOW_RATE_CHUNK, None),
                ("events", EVENTS_DTYPE, _LOW_RATE_CHUNK, None),
            )
        }

    def _write_gauges(self, block: NDArray[np.void]) -> None:
        self._streams["gauges"].add(block)
        if self._streams["gauges"].write(whole_chunks_only=True):
            self.flush()  # a whole chunk went out: make it durable now

    def _write_command(self, block: NDArray[np.void]) -> None:
        self._streams["command"].add(block)
        if self._streams["command"].write(whole_chunks_only=True):
            self.flush()

    def _write_drive(self, block: NDArray[np.void]) -> None:
        self._streams["drive"].add(block)

    def _write_event(self, t_ns: int, kind: str, text: str) -> None:
        row = np.array([(t_ns, kind, text)], dtype=EVENTS_DTYPE)
        self._streams["events"].add(row)

    def _flush(self) -> None:
        self._streams["drive"].write(whole_chunks_only=False)
        self._streams["events"].write(whole_chunks_only=False)
        self._h5.flush()

    def _close(self) -> None:
        try:
            for stream in self._streams.values():
                stream.write(whole_chunks_only=False)
        finally:
            self._h5.close()


def _open(path: Path, salvage: bool) -> tuple[h5py.File, list[str]]:
    try:
        return h5py.File(path, "r"), []
    except FileNotFoundError:
        raise
    except OSError as err:
        if "already open for write" not in str(err):
            raise CorruptRecordingError(
                f"{path}: not a readable HDF5 file ({one_line(str(err))})"
            ) from err
    line = "the file was not closed by its writer (killed, or still recording)"
    if not salvage:
        raise TruncatedRecordingError(f"{path}: {line}; run `labstand recover {path} -o FIXED.h5`")
    try:
        return h5py.File(path, "r", swmr=True), [f"recovered: {line}"]
    except OSError as err:
        raise CorruptRecordingError(
            f"{path}: {line}, and it cannot be salvaged: {one_line(str(err))}"
        ) from err


def _dataset(
    h5: h5py.File, path: Path, name: str, dtype: np.dtype[Any], file_size: int
) -> h5py.Dataset:
    """A stream's dataset, checked (a hard link to a 1-D dataset of our fields and size)."""
    link = h5.get(name, getlink=True)
    if link is None:
        raise MissingChannelError(f"{path}: no dataset /{name}")
    if not isinstance(link, h5py.HardLink):  # a soft or external link: not ours to follow
        raise CorruptRecordingError(f"{path}: /{name} is a {type(link).__name__}, not a dataset")
    ds = h5[name]
    if not isinstance(ds, h5py.Dataset):
        raise CorruptRecordingError(f"{path}: /{name} is a {type(ds).__name__}, not a dataset")
    check_dataset(ds, str(path), dtype, file_size)
    return ds


def _read_stream(ds: h5py.Dataset, path: Path, dtype: np.dtype[Any], repairs: list[str]) -> Any:
    try:
        return _read_rows(ds, dtype, repairs)
    except OSError as err:  # a chunk that fails its filter (gzip) or checksum
        raise CorruptRecordingError(
            f"{path}: dataset {ds.name} cannot be read: {one_line(str(err))}"
        ) from err


def _read_rows(ds: h5py.Dataset, dtype: np.dtype[Any], repairs: list[str]) -> NDArray[np.void]:
    if dtype.hasobject:
        raw = ds.fields(list(dtype.names or ()))[...]
        out = np.empty(len(raw), dtype=dtype)
        for field in dtype.names or ():
            column = raw[field]
            if dtype[field] == np.dtype(object):
                column = [_text(v, i, f"{ds.name}.{field}", repairs) for i, v in enumerate(column)]
            out[field] = column
        return out
    if ds.dtype == dtype:
        return np.asarray(ds[...])
    return np.asarray(ds.fields(list(dtype.names or ()))[...]).astype(dtype)


def _text(value: Any, row: int, where: str, repairs: list[str]) -> Any:
    """A string field's value; bytes that are not UTF-8 are kept, marked, and said so."""
    if not isinstance(value, bytes):
        return value
    try:
        return value.decode()
    except UnicodeDecodeError:
        repairs.append(f"{where} row {row} is not UTF-8: decoded with replacement characters")
        return value.decode(errors="replace")


#: What h5py raises for a damaged file: a failed checksum opening an object (KeyError),
#: unreadable metadata or data (OSError, RuntimeError), a type it cannot convert.
_H5_ERRORS = (KeyError, OSError, RuntimeError, TypeError, ValueError)
STREAM_DTYPES = {
    "gauges": GAUGES_DTYPE,
    "command": COMMAND_DTYPE,
    "drive": DRIVE_DTYPE,
    "events": EVENTS_DTYPE,
}


@dataclass(frozen=True)
class CheckedHdf5:
    """An open HDF5 recording that passed every check, before any row is read."""

    metadata: RecordingMetadata
    datasets: dict[str, h5py.Dataset]
    repairs: list[str]


@contextmanager
def checked_hdf5(path: Path, *, salvage: bool = False) -> Iterator[CheckedHdf5]:
    """The one validation of an HDF5 recording, for every read path (whole or a window).

    The global heaps (a hang in the library), the attributes' types, the metadata's
    schema, each stream's link, shape, fields and size against the file's; what h5py
    raises inside the block (a damaged chunk, a failed checksum) becomes
    CorruptRecordingError.
    """
    check_global_heaps(path)
    h5, repairs = _open(path, salvage)
    try:
        with h5:
            yield CheckedHdf5(*_validate(h5, path), repairs)
    except RecordingError:
        raise
    except _H5_ERRORS as err:
        message = one_line(str(err).strip("'\"")) or type(err).__name__
        raise CorruptRecordingError(f"{path}: damaged HDF5 file: {message}") from err


def _validate(h5: h5py.File, path: Path) -> tuple[RecordingMetadata, dict[str, h5py.Dataset]]:
    where = str(path)
    version = int_attr(h5.attrs, "schema_version", where)
    if version > SCHEMA_VERSION:
        raise SchemaVersionError(
            f"{path}: schema version {version} is newer than this labstand reads "
            f"({SCHEMA_VERSION}); update labstand"
        )
    metadata = RecordingMetadata.from_json(text_attr(h5.attrs, "metadata_json", where), where)
    size = path.stat().st_size
    datasets = {name: _dataset(h5, path, name, dt, size) for name, dt in STREAM_DTYPES.items()}
    return metadata, datasets


def read_hdf5(path: Path, *, salvage: bool = False) -> Recording:
    """Read an HDF5 recording (see ``open_recording``)."""
    with checked_hdf5(path, salvage=salvage) as h5:
        streams = {
            name: _read_stream(ds, path, STREAM_DTYPES[name], h5.repairs)
            for name, ds in h5.datasets.items()
        }
    return Recording(
        path=path,
        metadata=h5.metadata,
        gauges=streams["gauges"],
        command=streams["command"],
        drive=streams["drive"],
        events_array=streams["events"],
        repairs=h5.repairs,
    )
