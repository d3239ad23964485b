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
    "listed",
    "one_line",
    "shown",
    "size_text",
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


def shown(value: object, limit: int = 60) -> str:
    """A value for a one-line message: its repr cut to ``limit`` characters.

    An integer too long for ``repr`` (Python refuses more than 4300 digits) is given by
    its size instead.
    """
    if isinstance(value, int) and value.bit_length() > 200:
        return f"an integer of {value.bit_length()} bits"
    text = repr(value)
    return text if len(text) <= limit else f"{text[: limit - 3]}..."


def listed(names: list[str], limit: int = 12) -> str:
    """Names for a one-line message: the first ``limit``, then how many in all."""
    if len(names) <= limit:
        return ", ".join(names)
    return f"{', '.join(names[:limit])}, … ({len(names)} in all)"


def size_text(n: int) -> str:
    """Bytes in a short human form (``12 kB``, ``3.7 TB``)."""
    value = float(n)
    for unit in ("bytes", "kB", "MB", "GB", "TB"):
        if value < 1000 or unit == "TB":
            return f"{n} bytes" if unit == "bytes" else f"{value:.3g} {unit}"
        value /= 1000
    raise AssertionError("unreachable")


def one_line(text: str, limit: int = 200) -> str:
    """A library's message for ours: control characters escaped, cut to ``limit``.

    npTDMS puts object paths read from the file into its messages, pandas ends them with
    a newline; an error must stay one line on stderr.
    """
    clean = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text.strip())
    return clean if len(clean) <= limit else f"{clean[: limit - 3]}..."
