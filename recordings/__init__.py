"""Recordings: one schema (docs/recording-format.md), MCAP and HDF5 files, imports.

``open_writer(path, metadata)`` streams a recording into ``.mcap`` or ``.h5``;
``open_recording(path)`` reads ``.mcap``, ``.h5``/``.hdf5``, ``.csv``, ``.parquet`` and
``.tdms`` into a checked ``Recording`` (``.metadata``, ``.frame()``, ``.drive_states()``,
``.events()``).
Which suffix is read and written by what: one table, ``recordings.formats.FORMATS``.

Exceptions::

    ValueError
     └── RecordingError               anything wrong with a recording; names the file
          ├── UnknownFormatError      no reader/writer for the file's suffix
          ├── WriterClosedError       a write after close()
          ├── SchemaVersionError      written by a newer schema than this software reads
          ├── MissingChannelError     a required stream, channel or metadata is absent
          ├── TruncatedRecordingError the writer was killed: run ``labstand recover``
          ├── CorruptRecordingError   a failed checksum, bytes that do not decode
          ├── InvalidDataError        NaNs, time or sequence not increasing, bad blocks
          ├── ImportMappingError      CSV/TDMS columns that cannot be mapped, bad CSV lines
          └── WindowError             a time window outside the recording (recordings.window)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Lazy re-exports (PEP 562): importing one module of the package (``recordings.errors``,
# say) must not load the heavy ones (numba, scipy, pandas, h5py, ...) through it.
# A name here must not name both an object and a submodule (importing the submodule
# would rebind it to the module): sim.identify, whose ``diagnose`` is both, stays eager.
_EXPORTS = {
    "csvio": "recordings.csvio",
    "hdf5io": "recordings.hdf5io",
    "mcap_reader": "recordings.mcap_reader",
    "mcap_writer": "recordings.mcap_writer",
    "tdmsio": "recordings.tdmsio",
    "tables": "recordings.tables",
    "RecordingWriter": "recordings.base",
    "open_writer": "recordings.base",
    "CorruptRecordingError": "recordings.errors",
    "ImportMappingError": "recordings.errors",
    "InvalidDataError": "recordings.errors",
    "MissingChannelError": "recordings.errors",
    "RecordingError": "recordings.errors",
    "SchemaVersionError": "recordings.errors",
    "TruncatedRecordingError": "recordings.errors",
    "UnknownFormatError": "recordings.errors",
    "WriterClosedError": "recordings.errors",
    "Recording": "recordings.recording",
    "open_recording": "recordings.recording",
    "COMMAND_DTYPE": "recordings.schema",
    "DRIVE_DTYPE": "recordings.schema",
    "GAUGES_DTYPE": "recordings.schema",
    "SCHEMA_VERSION": "recordings.schema",
    "Backend": "recordings.schema",
    "Effect": "recordings.schema",
    "RecordingMetadata": "recordings.schema",
    "make_metadata": "recordings.schema",
    "unwrap_u16": "recordings.schema",
}

if TYPE_CHECKING:
    from recordings import csvio, hdf5io, mcap_reader, mcap_writer, tdmsio
    from recordings.base import RecordingWriter, open_writer
    from recordings.errors import (
        CorruptRecordingError,
        ImportMappingError,
        InvalidDataError,
        MissingChannelError,
        RecordingError,
        SchemaVersionError,
        TruncatedRecordingError,
        UnknownFormatError,
        WriterClosedError,
    )
    from recordings.recording import Recording, open_recording
    from recordings.schema import (
        COMMAND_DTYPE,
        DRIVE_DTYPE,
        GAUGES_DTYPE,
        SCHEMA_VERSION,
        Backend,
        Effect,
        RecordingMetadata,
        make_metadata,
        unwrap_u16,
    )


# The same PEP 562 hook in every package __init__ (drivers, sim, sim.effects, sim.hardware,
# recordings): a shared helper would have to live in the lowest layer, drivers.
def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'recordings' has no attribute {name!r}")
    if module == f"{__name__}.{name}":  # a submodule
        return importlib.import_module(module)
    return getattr(importlib.import_module(module), name)


__all__ = [
    "COMMAND_DTYPE",
    "DRIVE_DTYPE",
    "GAUGES_DTYPE",
    "SCHEMA_VERSION",
    "Backend",
    "CorruptRecordingError",
    "Effect",
    "ImportMappingError",
    "InvalidDataError",
    "MissingChannelError",
    "Recording",
    "RecordingError",
    "RecordingMetadata",
    "RecordingWriter",
    "SchemaVersionError",
    "TruncatedRecordingError",
    "UnknownFormatError",
    "WriterClosedError",
    "csvio",
    "hdf5io",
    "make_metadata",
    "mcap_reader",
    "mcap_writer",
    "open_recording",
    "open_writer",
    "tables",
    "tdmsio",
    "unwrap_u16",
]
