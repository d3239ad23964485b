"""Every recording format in one table: suffix → reader and writers, imported when used.

``FORMATS`` is the one place a format is made known (python-can's ``MESSAGE_READERS``):
each entry names its reader and writers as ``"module:attribute"`` strings, and a module is
imported only when a file of its suffix is read or written, so reading an MCAP file loads
no h5py, nptdms or pyarrow (the commands' start-up time, docs/benchmarks.md). Nothing
registers itself on import: a format missing here is missing everywhere, visibly.

Two kinds of writer: ``writer``, a streaming ``RecordingWriter`` (``labstand run``
records into it block by block), and ``table_writer``, which writes a whole recording as
one table on the gauge clock (``labstand convert`` to CSV or Parquet).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Literal

from recordings.errors import UnknownFormatError

if TYPE_CHECKING:
    from recordings.base import RecordingWriter
    from recordings.recording import Recording

__all__ = [
    "FORMATS",
    "Format",
    "format_for",
    "reader_for",
    "suffixes",
    "writer_for",
]

Role = Literal["read", "write", "table"]


@dataclass(frozen=True)
class Format:
    """One file format: its name and where its reader and writers live.

    Attributes
    ----------
    name
        What a user calls it (``"MCAP"``).
    reader
        ``"module:function"``, ``function(path, *, salvage=False) -> Recording``; or None.
    writer
        ``"module:Class"``, a streaming ``RecordingWriter(path, metadata, **options)``;
        or None.
    table_writer
        ``"module:function"``, ``function(recording, path, metadata)`` writing a whole
        recording as one table; or None.
    """

    name: str
    reader: str | None = None
    writer: str | None = None
    table_writer: str | None = None

    def target(self, role: Role) -> str | None:
        """The ``"module:attribute"`` of a role, or None if the format lacks it."""
        return {"read": self.reader, "write": self.writer, "table": self.table_writer}[role]

    def load(self, role: Role) -> Any:
        """Import the role's module and return its attribute (KeyError: no such role)."""
        target = self.target(role)
        if target is None:
            raise KeyError(f"{self.name} has no {role} role")
        module, _, attribute = target.partition(":")
        return getattr(importlib.import_module(module), attribute)


_MCAP = Format(
    "MCAP", "recordings.mcap_reader:read_mcap", "recordings.mcap_writer:McapRecordingWriter"
)
_HDF5 = Format("HDF5", "recordings.hdf5io:read_hdf5", "recordings.hdf5io:Hdf5RecordingWriter")

#: suffix (lower case, with the dot) -> its format. Read-only: change it here, in code.
FORMATS: Mapping[str, Format] = MappingProxyType(
    {
        ".mcap": _MCAP,
        ".h5": _HDF5,
        ".hdf5": _HDF5,
        ".csv": Format(
            "CSV", "recordings.csvio:read_csv", table_writer="recordings.tables:write_table"
        ),
        ".parquet": Format(
            "Parquet",
            "recordings.tables:read_parquet",
            table_writer="recordings.tables:write_table",
        ),
        ".tdms": Format("TDMS", "recordings.tdmsio:read_tdms"),  # foreign: read only
    }
)


def suffixes(*roles: Role) -> list[str]:
    """The suffixes with any of these roles, sorted (every suffix when none is given)."""
    return sorted(s for s, f in FORMATS.items() if not roles or any(f.target(r) for r in roles))


def format_for(path: Path, *roles: Role) -> Format:
    """The format of ``path``'s suffix, having one of ``roles``.

    Raises
    ------
    UnknownFormatError
        No format of that suffix has any of the roles; the message lists those that do.
    """
    suffix = path.suffix.lower()
    found = FORMATS.get(suffix)
    if found is None or not any(found.target(r) for r in roles):
        verb = "read" if roles == ("read",) else "write"
        raise UnknownFormatError(
            f"{path}: cannot {verb} {suffix or 'files without a suffix'!r}; "
            f"use one of {', '.join(suffixes(*roles))}"
        )
    return found


def reader_for(path: Path) -> Callable[..., Recording]:
    """The reader function for ``path``'s suffix (its module imported now)."""
    reader: Callable[..., Recording] = format_for(path, "read").load("read")
    return reader


def writer_for(path: Path) -> Callable[..., RecordingWriter]:
    """The streaming writer class for ``path``'s suffix (its module imported now)."""
    writer: Callable[..., RecordingWriter] = format_for(path, "write").load("write")
    return writer
