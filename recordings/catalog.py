"""What a recording says about itself, read without its samples (``labstand ls``).

Each format keeps the metadata at a place found without reading the streams, and the run's
time span nearly so:

* MCAP: the summary's metadata index gives the ``labstand.recording`` record; the span is
  the first and the last ``/gauges`` batch (the chunk index finds the last chunk, which
  alone is decompressed).
* HDF5: the root's ``metadata_json`` attribute; the first and last row's ``t_ns``.
* CSV: the ``# labstand-metadata:`` first line; the last line's ``t_s`` (read from the
  file's end).
* Parquet: the footer's key-value metadata and the ``t_ns`` column's statistics.

A file whose metadata cannot be read this way is left out with its reason (``Entry.error``);
``labstand doctor`` and ``info`` say more.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from recordings.errors import RecordingError
from recordings.formats import suffixes
from recordings.schema import RecordingMetadata

__all__ = ["HEADS", "SUFFIXES", "Entry", "entries", "read_entry"]

#: The formats labstand writes (``recordings.formats``; TDMS is a foreign format: it
#: carries no labstand metadata). Each has a metadata reader below (a test holds them equal).
SUFFIXES = tuple(suffixes("write", "table"))
_TAIL_BYTES = 4096
#: ``recordings.csvio.METADATA_TAG`` (that module imports pandas: 0.3 s)
CSV_METADATA_TAG = "# labstand-metadata: "


@dataclass(frozen=True)
class Entry:
    """One recording's metadata and span (s), or why it could not be read."""

    path: Path
    metadata: RecordingMetadata | None
    duration_s: float | None = None
    error: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The row ``labstand ls --json`` prints."""
        m = self.metadata
        if m is None:
            return {"path": str(self.path), "error": self.error}
        signal = dict(m.signal) if m.signal else None
        return {
            "path": str(self.path),
            "start_time_utc": m.start_time_utc,
            "duration_s": self.duration_s,
            "backend": str(m.backend),
            "signal": signal,
            "mass_kg": m.mass_kg,
            "operator": m.operator,
            "sample": m.sample,
            "tags": list(m.tags),
            "run_id": m.run_id,
            "note": m.operator_note,
            "effects": [e.name for e in m.effects],
        }


def entries(paths: Iterable[Path]) -> list[Entry]:
    """``read_entry`` of each path of a known suffix, in the order given."""
    return [read_entry(p) for p in paths if p.suffix.lower() in SUFFIXES]


def read_entry(path: Path) -> Entry:
    """The metadata and span of one recording, or the reason it cannot be read."""
    head = HEADS.get(path.suffix.lower())
    if head is None:
        return Entry(path, None, error=f"no labstand recording: {path.suffix or 'no suffix'!r}")
    where = str(path)
    try:
        text, span = head(path)
        meta = RecordingMetadata.from_json(text, where)
    except OSError as err:  # h5py's own OSErrors have no errno: their text then
        return Entry(path, None, error=err.strerror or " ".join(str(err).split()))
    except (RecordingError, ValueError, KeyError, IndexError, TypeError) as err:
        return Entry(path, None, error=" ".join(str(err).split()) or type(err).__name__)
    return Entry(path, meta, None if span is None else span / 1e9)


def _mcap(path: Path) -> tuple[str, int | None]:
    from mcap.reader import make_reader

    from recordings.mcap_writer import GAUGE_CODEC, METADATA_NAME

    with path.open("rb") as f:
        reader = make_reader(f)
        if reader.get_summary() is None:
            raise RecordingError(f"{path}: no summary (a killed run: labstand doctor)")
        text = next(
            (m.metadata.get("json") for m in reader.iter_metadata() if m.name == METADATA_NAME),
            None,
        )
        if text is None:
            raise RecordingError(f"{path}: no labstand metadata record")
        ends = []
        for reverse in (False, True):
            found = next(reader.iter_messages(topics=["/gauges"], reverse=reverse), None)
            if found is None:
                return text, None
            ends.append(GAUGE_CODEC.decode_many([found[2].data], str(path))["t_ns"])
    return text, int(ends[1][-1]) - int(ends[0][0])


def _hdf5(path: Path) -> tuple[str, int | None]:
    import h5py

    with h5py.File(path, "r") as h5:
        raw = h5.attrs["metadata_json"]
        text = raw.decode() if isinstance(raw, bytes) else str(raw)
        g = h5["gauges"]
        span = int(g[-1]["t_ns"]) - int(g[0]["t_ns"]) if len(g) else None
    return text, span


def _csv(path: Path) -> tuple[str, int | None]:
    with path.open("rb") as f:
        first = f.readline().decode("utf-8")
        if not first.startswith(CSV_METADATA_TAG):
            raise RecordingError(f"{path}: no labstand metadata line (a foreign CSV: import it)")
        size = f.seek(0, os.SEEK_END)
        f.seek(max(0, size - _TAIL_BYTES))
        lines = f.read().decode("utf-8", "replace").splitlines()
        f.seek(len(first.encode()))
        for raw in f:  # past the preamble (events, drive polls) and the header
            if raw.startswith(b"t_s,"):
                break
        first_t = next(_times([f.readline().decode("utf-8", "replace")]), None)
    last_t = next(_times(reversed(lines)), None)
    span = None
    if first_t is not None and last_t is not None:
        span = round((last_t - first_t) * 1e9)
    return first[len(CSV_METADATA_TAG) :], span


def _times(lines: Iterable[str]) -> Iterator[float]:
    """The leading number of each sample line (t_s), skipping the preamble and header."""
    for line in lines:
        field = line.split(",", 1)[0].strip()
        if field and not line.startswith("#"):
            try:
                yield float(field)
            except ValueError:
                continue


def _parquet(path: Path) -> tuple[str, int | None]:
    import pyarrow.parquet as pq

    meta = pq.read_metadata(path)
    extra = {k.decode(): v.decode() for k, v in (meta.metadata or {}).items()}
    if "labstand.metadata" not in extra:
        raise RecordingError(f"{path}: no labstand.metadata (not a labstand export)")
    lo = hi = None
    column = meta.schema.names.index("t_ns") if "t_ns" in meta.schema.names else None
    for i in range(meta.num_row_groups) if column is not None else ():
        stats = meta.row_group(i).column(column).statistics
        if stats is None or not stats.has_min_max:
            return extra["labstand.metadata"], None
        lo = stats.min if lo is None else min(lo, stats.min)
        hi = stats.max if hi is None else max(hi, stats.max)
    return extra["labstand.metadata"], None if lo is None or hi is None else int(hi) - int(lo)


#: suffix -> its metadata (JSON text) and span (ns, or None), read without the samples.
HEADS: dict[str, Callable[[Path], tuple[str, int | None]]] = {
    ".mcap": _mcap,
    ".h5": _hdf5,
    ".hdf5": _hdf5,
    ".csv": _csv,
    ".parquet": _parquet,
}
