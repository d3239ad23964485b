"""Checks on an HDF5 file before h5py reads it: the faults the HDF5 library does not catch.

* A global heap collection (where HDF5 keeps variable-length strings: labstand's string
  attributes and event texts) whose object list contains a zero-length step: the
  library's parser (``H5HG__cache_heap_deserialize``, HDF5 1.8 to 2.0) advances by each
  object's stored size and never stops when that size is 0 (or wraps to 0), so reading
  any string attribute hangs forever. ``check_global_heaps`` walks every collection as
  the library does and refuses such a file first.
* A dataset whose shape claims more rows than the file can hold (numpy would try to
  allocate terabytes), whose chunks are as large, or whose fields have the wrong type.
* Attributes of the wrong type or shape (a ``schema_version`` that is an array).
"""

from __future__ import annotations

import mmap
import struct
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from recordings.errors import CorruptRecordingError, MissingChannelError, shown, size_text

__all__ = ["check_dataset", "check_global_heaps", "int_attr", "text_attr"]

_GCOL = b"GCOL"
_COLLECTION_HEAD = 16  # "GCOL", version 1, 3 reserved bytes, collection size (8 bytes)
_OBJECT = struct.Struct("<HH4xQ")  # heap index, reference count, reserved, object size
_U64 = 2**64
#: Deflate expands at most 1032-fold; a filtered dataset can hold no more than that.
MAX_FILTER_RATIO = 1032


def check_global_heaps(path: Path) -> None:
    """Raise CorruptRecordingError for a heap collection the HDF5 library would loop on."""
    with path.open("rb") as f:
        if path.stat().st_size < _COLLECTION_HEAD:
            return  # h5py refuses it as "not an HDF5 file"
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
            pos = data.find(_GCOL)
            while pos >= 0:
                problem = _collection_problem(data, pos)
                if problem is not None:
                    raise CorruptRecordingError(
                        f"{path}: global heap collection at byte {pos} is damaged: {problem}; "
                        "the HDF5 library would never finish reading it"
                    )
                pos = data.find(_GCOL, pos + 1)


def _collection_problem(data: mmap.mmap, start: int) -> str | None:
    """Walk one collection's objects as the library does; the step that cannot advance.

    A match of "GCOL" that is no collection (in compressed data, say) is left alone
    unless its walk would hang the library, which random bytes almost never do.
    """
    if start + _COLLECTION_HEAD > len(data) or data[start + 4] != 1:
        return None
    (size,) = struct.unpack_from("<Q", data, start + 8)
    end = start + size
    if end > len(data):
        return None  # the library refuses to read past the end of the file
    pos = start + _COLLECTION_HEAD
    while pos + _OBJECT.size <= end:
        index, _, length = _OBJECT.unpack_from(data, pos)
        # The library's arithmetic is size_t: align to 8 bytes, add the header (objects
        # 1...), or take the free-space object's (index 0) size as it is; all modulo 2**64.
        step = length if index == 0 else (_OBJECT.size + ((length + 7) % _U64 // 8 * 8)) % _U64
        if step == 0 or step >= _U64 // 2:
            return f"object {index} at byte {pos} has size {length}"
        pos += step
    return None


def check_dataset(ds: h5py.Dataset, where: str, dtype: np.dtype[Any], file_size: int) -> None:
    """Shape, field types and size of a stream's dataset, before any of it is read."""
    name = ds.name
    if ds.ndim != 1:
        raise CorruptRecordingError(f"{where}: dataset {name} has shape {ds.shape}, expected 1-D")
    names = ds.dtype.names or ()
    missing = [f for f in dtype.names or () if f not in names]
    if missing:
        raise MissingChannelError(f"{where}: {name} has no field(s) {', '.join(missing)}")
    for field in dtype.names or ():
        found = ds.dtype[field]
        if dtype[field] == np.dtype(object):
            ok = h5py.check_string_dtype(found) is not None
        else:
            ok = found.kind in "biuf" and found.shape == ()
        if not ok:
            raise CorruptRecordingError(
                f"{where}: dataset {name} field {field!r} has type {found}, "
                f"expected {'a string' if dtype[field] == np.dtype(object) else dtype[field]}"
            )
    filtered = ds.id.get_create_plist().get_nfilters() > 0
    limit = file_size * (MAX_FILTER_RATIO if filtered else 1)
    row = ds.dtype.itemsize
    if ds.shape[0] * row > limit:
        raise CorruptRecordingError(
            f"{where}: dataset {name} has shape {ds.shape}, larger than the file "
            f"({size_text(file_size)}) can hold ({size_text(ds.shape[0] * row)})"
        )
    if ds.chunks is not None and ds.chunks[0] * row > max(limit, 2**20):
        raise CorruptRecordingError(
            f"{where}: dataset {name} has chunks of {ds.chunks[0]} rows "
            f"({size_text(ds.chunks[0] * row)}), larger than the file ({size_text(file_size)})"
        )


def _attr(attrs: h5py.AttributeManager, key: str, where: str) -> Any:
    if key not in attrs:
        raise MissingChannelError(f"{where}: no labstand metadata ({key} attribute)")
    value = attrs[key]
    if np.ndim(value) != 0:
        raise CorruptRecordingError(
            f"{where}: attribute {key} is an array of shape {np.shape(value)}, expected a scalar"
        )
    return value.item() if isinstance(value, np.ndarray) else value


def int_attr(attrs: h5py.AttributeManager, key: str, where: str) -> int:
    """A whole-number scalar attribute."""
    value = _attr(attrs, key, where)
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise CorruptRecordingError(
            f"{where}: attribute {key} must be a whole number, got {shown(value)}"
        )
    return int(value)


def text_attr(attrs: h5py.AttributeManager, key: str, where: str) -> str:
    """A string scalar attribute (UTF-8)."""
    value = _attr(attrs, key, where)
    if isinstance(value, bytes):
        try:
            value = value.decode()
        except UnicodeDecodeError as err:
            raise CorruptRecordingError(f"{where}: attribute {key} is not UTF-8: {err}") from err
    if not isinstance(value, str):
        raise CorruptRecordingError(f"{where}: attribute {key} must be text, got {shown(value)}")
    return value
