"""The errors of the recordings package (the tree is drawn in ``recordings/__init__.py``).

Every message is one line that names the file and what is wrong with it.
"""

from __future__ import annotations

__all__ = [
    "CorruptRecordingError",
    "ImportMappingError",
    "InvalidDataError",
    "MissingChannelError",
    "RecordingError",
    "SchemaVersionError",
    "TruncatedRecordingError",
    "UnknownFormatError",
    "WriterClosedError",
]


class RecordingError(ValueError):
    """A recording that cannot be written or read as asked."""


class UnknownFormatError(RecordingError):
    """A file suffix no reader or writer is registered for."""


class WriterClosedError(RecordingError):
    """A write to a writer that was already closed."""


class SchemaVersionError(RecordingError):
    """A recording written with a newer schema than this software reads."""


class MissingChannelError(RecordingError):
    """A stream, channel or metadata block the schema requires is absent."""


class TruncatedRecordingError(RecordingError):
    """The file ends in the middle (the writer was killed); ``labstand recover`` repairs it."""


class CorruptRecordingError(RecordingError):
    """Bytes that fail their checksum or do not decode."""


class InvalidDataError(RecordingError):
    """Decoded data that breaks the schema: NaNs, non-monotonic time, unequal lengths."""


class ImportMappingError(RecordingError):
    """A foreign file (CSV, TDMS) whose columns cannot be mapped onto the schema."""
