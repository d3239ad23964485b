"""Recordings: one schema (docs/recording-format.md), MCAP and HDF5 files, imports.

``open_writer(path, metadata)`` streams a recording into ``.mcap`` or ``.h5``;
``open_recording(path)`` reads ``.mcap``, ``.h5``/``.hdf5``, ``.csv``, ``.parquet`` and
``.tdms`` into a checked ``Recording`` (``.metadata``, ``.frame()``, ``.drive_states()``,
``.events()``).

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

from recordings import csvio, hdf5io, mcap_reader, mcap_writer, tables, tdmsio
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
