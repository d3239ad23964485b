"""Where a diagnosis came from: its recordings (hashed), masses, stand, signals, version, date.

One dict that ``diagnose --json``, ``result.json`` and the HTML page all read, so a
report a researcher signs names exactly the files and settings behind its numbers.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

__all__ = ["BUILT_IN_STAND", "RecordingSource", "build_provenance", "sha256_of"]

#: What the provenance says when no ``--stand`` file was given.
BUILT_IN_STAND = "built-in default (the paper's stand)"
_CHUNK = 1 << 20


def sha256_of(path: Path) -> str:
    """The file's SHA-256, hex (read in chunks: recordings can be large)."""
    digest = hashlib.sha256()
    with path.open("rb") as stream:
        while chunk := stream.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


@dataclass(frozen=True)
class RecordingSource:
    """One recording as the diagnosis read it.

    ``metadata``: the recording's ``RecordingMetadata.to_dict()`` (only its signal,
    backend, start time, effects and writer are kept).
    """

    path: Path
    name: str
    mass_kg: float
    mass_source: str
    metadata: Mapping[str, Any]


def _recording(source: RecordingSource) -> dict[str, Any]:
    meta = source.metadata
    return {
        "path": str(source.path),
        "name": source.name,
        "sha256": sha256_of(source.path),
        "bytes": source.path.stat().st_size,
        "mass_kg": source.mass_kg,
        "mass_source": source.mass_source,
        "backend": meta.get("backend"),
        "start_time_utc": meta.get("start_time_utc"),
        "sample_rate_hz": meta.get("sample_rate_hz"),
        # None for imports and manual runs: the recording does not say how it was driven.
        "signal": meta.get("signal"),
        "simulated_effects": meta.get("effects") or [],
        "written_by": meta.get("software_version") or None,
    }


def build_provenance(
    sources: list[RecordingSource],
    stand_file: Path | None,
    params: str,
    now: datetime | None = None,
) -> dict[str, Any]:
    """The provenance dict: JSON keys labstand_version, created_utc, stand, recordings."""
    import labstand

    created = (now or datetime.now(UTC)).astimezone(UTC)
    return {
        "labstand_version": labstand.__version__,
        "created_utc": created.isoformat(timespec="seconds"),
        "stand": {
            "file": str(stand_file) if stand_file is not None else None,
            "sha256": sha256_of(stand_file) if stand_file is not None else None,
            "label": str(stand_file) if stand_file is not None else BUILT_IN_STAND,
            "parameter_set": params,
        },
        "recordings": [_recording(s) for s in sources],
    }
