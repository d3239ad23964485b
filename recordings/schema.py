# Over 400 lines: one schema (every stream, dtype, unit and metadata field) that all formats read.
"""Schema version 1 of a recording: streams, their numpy dtypes, units, and the metadata.

See docs/recording-format.md. A recording holds four streams:

* ``gauges`` (the acquisition clock, 2 kHz): seq, t_ns, x_mm, u_mm, force_n, flags
* ``command`` (same clock): t_ns, x_cmd_mm
* ``drive`` (Modbus polling, tens of Hz): t_ns, position_mm, speed_mm_s, status_word,
  trip_code, enabled
* ``events``: t_ns, kind, text

Times are int64 nanoseconds since the start of the run (``start_time_utc``).
"""

from __future__ import annotations

import json
import socket
import uuid
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from enum import StrEnum
from typing import Any

import numpy as np
from numpy.typing import NDArray

from recordings.errors import CorruptRecordingError, InvalidDataError, SchemaVersionError, shown

__all__ = [
    "COMMAND_DTYPE",
    "DRIVE_DTYPE",
    "EVENT_KINDS",
    "GAUGES_DTYPE",
    "SCHEMA_VERSION",
    "STREAMS",
    "Backend",
    "Block",
    "ChannelInfo",
    "Effect",
    "RecordingMetadata",
    "as_block",
    "concat_blocks",
    "make_metadata",
    "software_version",
    "unwrap_u16",
]

SCHEMA_VERSION = 1

#: One gauge sample: the front end's sequence counter (unwrapped), device time, readings.
GAUGES_DTYPE = np.dtype(
    [
        ("seq", "<i8"),
        ("t_ns", "<i8"),
        ("x_mm", "<f8"),
        ("u_mm", "<f8"),
        ("force_n", "<f8"),
        ("flags", "u1"),
    ]
)
#: The planned drive position at the acquisition clock.
COMMAND_DTYPE = np.dtype([("t_ns", "<i8"), ("x_cmd_mm", "<f8")])
#: One poll of the drive converter over Modbus.
DRIVE_DTYPE = np.dtype(
    [
        ("t_ns", "<i8"),
        ("position_mm", "<f8"),
        ("speed_mm_s", "<f8"),
        ("status_word", "<u4"),
        ("trip_code", "<u4"),
        ("enabled", "?"),
    ]
)
STREAMS: dict[str, np.dtype[Any]] = {
    "gauges": GAUGES_DTYPE,
    "command": COMMAND_DTYPE,
    "drive": DRIVE_DTYPE,
}
#: Event kinds the software writes; others are allowed (free text).
EVENT_KINDS = ("start", "stop", "estop", "fault", "note", "repair")

#: Unit of every field (empty for counts and flags).
UNITS: dict[str, str] = {
    "seq": "",
    "t_ns": "ns",
    "x_mm": "mm",
    "u_mm": "mm",
    "force_n": "N",
    "flags": "",
    "x_cmd_mm": "mm",
    "position_mm": "mm",
    "speed_mm_s": "mm/s",
    "status_word": "",
    "trip_code": "",
    "enabled": "",
}

Block = NDArray[np.void] | Mapping[str, Any]
"""A block of samples: a structured array of the stream's dtype, or a dict of 1-D arrays
(one per field, equal lengths; fields missing from the dict are an error)."""


class Backend(StrEnum):
    """What produced a recording."""

    STAND = "stand"
    SIM = "sim"  # the simulated stand (protocol-level twin)
    SIMULATE = "simulate"  # ``labstand simulate``: the model alone, offline
    IMPORT = "import"  # converted from a foreign file (CSV, TDMS)


@dataclass(frozen=True)
class Effect:
    """A simulated effect and its parameters (names as STAND.md §5)."""

    name: str
    params: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class ChannelInfo:
    """One channel: its stream, unit and nominal rate (None: irregular)."""

    stream: str
    unit: str
    rate_hz: float | None


@dataclass(frozen=True)
class RecordingMetadata:
    """Everything a recording says about itself besides its samples.

    Attributes
    ----------
    stand_config
        The full stand configuration, ``StandConfig.to_dict()``; rebuild it with
        ``sim.config.config_from_dict``.
    backend
        What produced the samples.
    start_time_utc
        Start of the run, ISO 8601 with offset; every ``t_ns`` counts from here.
    sample_rate_hz
        Nominal rate of the gauges and command streams, Hz.
    signal
        ``SignalSpec.to_dict()`` of the drive signal, or None (imports, manual runs).
    effects
        Simulated effects (empty for the stand and for the baseline model).
    software_version, host
        Who wrote the file.
    operator_note
        Free text.
    source
        For imports: the original file name; otherwise empty.
    operator, sample
        Who ran it, and the sample (fibre) it ran on: free text, empty if not given.
    run_id
        A UUID made when the run was recorded; conversions and cuts keep it.
    tags
        Free labels (``--tag``), in the order given.
    schema_version
        Version of this schema the file follows.
    """

    stand_config: Mapping[str, Any]
    backend: Backend
    start_time_utc: str
    sample_rate_hz: float = 2000.0
    signal: Mapping[str, Any] | None = None
    effects: tuple[Effect, ...] = ()
    software_version: str = ""
    host: str = ""
    operator_note: str = ""
    source: str = ""
    schema_version: int = SCHEMA_VERSION
    operator: str = ""
    sample: str = ""
    run_id: str = ""
    tags: tuple[str, ...] = ()

    @property
    def channels(self) -> dict[str, ChannelInfo]:
        """Unit and rate of every channel, keyed ``stream.field``."""
        out: dict[str, ChannelInfo] = {}
        for stream, dtype in STREAMS.items():
            rate = self.sample_rate_hz if stream != "drive" else None
            for name in dtype.names or ():
                out[f"{stream}.{name}"] = ChannelInfo(stream, UNITS[name], rate)
        for name, unit in (("t_ns", "ns"), ("kind", ""), ("text", "")):
            out[f"events.{name}"] = ChannelInfo("events", unit, None)
        return out

    @property
    def mass_kg(self) -> float | None:
        """The weight stored with the run (its stand's default weight), None if unreadable."""
        try:
            weights, weight = self.stand_config["weights_kg"], self.stand_config["weight"]
            mass = float(weights[weight["default"]])
        except (KeyError, TypeError, ValueError):
            return None
        return mass if mass > 0 else None

    @property
    def start_time_ns(self) -> int:
        """Start time as nanoseconds since the Unix epoch."""
        start = datetime.fromisoformat(self.start_time_utc)
        if start.tzinfo is None:
            start = start.replace(tzinfo=UTC)
        delta = start - datetime(1970, 1, 1, tzinfo=UTC)
        return (delta.days * 86_400 + delta.seconds) * 10**9 + delta.microseconds * 1000

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able data (with the derived channel table, for readers of the file)."""
        return {
            "schema_version": self.schema_version,
            "backend": str(self.backend),
            "start_time_utc": self.start_time_utc,
            "sample_rate_hz": self.sample_rate_hz,
            "signal": dict(self.signal) if self.signal is not None else None,
            "effects": [{"name": e.name, "params": dict(e.params)} for e in self.effects],
            "software_version": self.software_version,
            "host": self.host,
            "operator_note": self.operator_note,
            "source": self.source,
            "operator": self.operator,
            "sample": self.sample,
            "run_id": self.run_id,
            "tags": list(self.tags),
            "stand_config": dict(self.stand_config),
            "channels": {
                k: {"stream": c.stream, "unit": c.unit, "rate_hz": c.rate_hz}
                for k, c in self.channels.items()
            },
        }

    def to_json(self) -> str:
        """``to_dict`` as compact JSON."""
        return json.dumps(self.to_dict(), separators=(",", ":"), sort_keys=True)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str) -> RecordingMetadata:
        """Check and build; ``where`` (the file) prefixes every complaint."""
        version_ = data.get("schema_version")
        if not isinstance(version_, int) or isinstance(version_, bool) or version_ < 1:
            raise CorruptRecordingError(
                f"{where}: metadata has no valid schema_version: {shown(version_)}"
            )
        if version_ > SCHEMA_VERSION:
            raise SchemaVersionError(
                f"{where}: schema version {version_} is newer than this labstand reads "
                f"({SCHEMA_VERSION}); update labstand"
            )
        rate = data.get("sample_rate_hz")
        if (
            isinstance(rate, bool)
            or not isinstance(rate, int | float)
            or not 0 < rate <= MAX_SAMPLE_RATE_HZ
        ):
            raise CorruptRecordingError(
                f"{where}: metadata sample_rate_hz must be a number of Hz in "
                f"(0, {MAX_SAMPLE_RATE_HZ:g}], got {shown(rate)}"
            )
        _check_signal(data.get("signal"), where)
        try:
            effects = tuple(
                Effect(str(e["name"]), {str(k): float(v) for k, v in e["params"].items()})
                for e in data.get("effects", [])
            )
            meta = cls(
                stand_config=dict(data["stand_config"]),
                backend=Backend(data["backend"]),
                start_time_utc=str(data["start_time_utc"]),
                sample_rate_hz=float(data["sample_rate_hz"]),
                signal=dict(data["signal"]) if data.get("signal") is not None else None,
                effects=effects,
                software_version=str(data.get("software_version", "")),
                host=str(data.get("host", "")),
                operator_note=str(data.get("operator_note", "")),
                source=str(data.get("source", "")),
                schema_version=version_,
                operator=str(data.get("operator", "")),
                sample=str(data.get("sample", "")),
                run_id=str(data.get("run_id", "")),
                tags=_tags(data.get("tags", []), where),
            )
            start_ns = meta.start_time_ns
        except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as err:
            raise CorruptRecordingError(f"{where}: metadata is unusable: {err!r}") from err
        if not 0 <= start_ns <= MAX_TIME_NS:
            raise CorruptRecordingError(
                f"{where}: metadata start_time_utc {shown(meta.start_time_utc)} is outside "
                "1970 … 2255 (nanoseconds since 1970 must fit 63 bits with a run after it)"
            )
        return meta

    @classmethod
    def from_json(cls, text: str | bytes, where: str) -> RecordingMetadata:
        """Parse ``to_json`` output."""
        if not isinstance(text, str | bytes):
            raise CorruptRecordingError(f"{where}: metadata is not text but {shown(text)}")
        try:
            data = json.loads(text)
        except (ValueError, UnicodeDecodeError) as err:
            raise CorruptRecordingError(f"{where}: metadata is not valid JSON: {err}") from err
        except RecursionError:  # json recurses once per nested array or object
            raise CorruptRecordingError(f"{where}: metadata JSON is nested too deeply") from None
        if not isinstance(data, dict):
            raise CorruptRecordingError(f"{where}: metadata is not a JSON object")
        return cls.from_dict(data, where)


def _tags(value: object, where: str) -> tuple[str, ...]:
    """Older files have no tags; a list of strings otherwise."""
    if not isinstance(value, list) or not all(isinstance(t, str) for t in value):
        raise CorruptRecordingError(
            f"{where}: metadata tags must be a list of text, got {shown(value)}"
        )
    return tuple(value)


#: The fastest nominal rate a recording may claim, Hz (the gauges stream at 2 kHz): a rate
#: sizes the grids that replay and compare allocate.
MAX_SAMPLE_RATE_HZ = 1e6
#: Times of a run (``t_ns``) lie within ±2⁵³ ns (104 days): exact as float seconds, and a
#: start time plus any of them still fits the 63 bits of an MCAP log time.
MAX_RUN_TIME_NS = 2**53
#: Start times (ns since 1970) up to this leave room for a run of MAX_RUN_TIME_NS.
MAX_TIME_NS = 2**63 - 1 - MAX_RUN_TIME_NS
_SIGNAL_NUMBERS = ("amplitude_mm", "frequency_hz")


def _check_signal(signal: Any, where: str) -> None:
    """The metadata's drive signal: None, or an object with a shape and its numbers."""
    if signal is None:
        return
    if not isinstance(signal, dict):
        raise CorruptRecordingError(
            f"{where}: metadata signal must be an object, got {shown(signal)}"
        )
    missing = [k for k in ("shape", *_SIGNAL_NUMBERS, "cycles") if k not in signal]
    if missing:
        raise CorruptRecordingError(f"{where}: metadata signal lacks {', '.join(missing)}")
    if not isinstance(signal["shape"], str):
        raise CorruptRecordingError(
            f"{where}: metadata signal shape must be text, got {shown(signal['shape'])}"
        )
    for key in _SIGNAL_NUMBERS:
        value = signal[key]
        if isinstance(value, bool) or not isinstance(value, int | float) or abs(value) > 1e300:
            raise CorruptRecordingError(
                f"{where}: metadata signal {key} must be a number, got {shown(value)}"
            )
    cycles = signal["cycles"]
    if isinstance(cycles, bool) or not isinstance(cycles, int) or abs(cycles) > 2**53:
        raise CorruptRecordingError(
            f"{where}: metadata signal cycles must be a whole number, got {shown(cycles)}"
        )


def software_version() -> str:
    """The installed labstand version (recordings may not import labstand itself)."""
    from importlib.metadata import PackageNotFoundError, version  # imports email: lazily

    try:
        return version("labstand")
    except PackageNotFoundError:
        return "0+unknown"


def make_metadata(
    stand_config: Mapping[str, Any],
    backend: Backend | str,
    *,
    sample_rate_hz: float = 2000.0,
    signal: Mapping[str, Any] | None = None,
    effects: tuple[Effect, ...] = (),
    operator_note: str = "",
    source: str = "",
    start: datetime | None = None,
    operator: str = "",
    sample: str = "",
    tags: tuple[str, ...] = (),
) -> RecordingMetadata:
    """Metadata for a new recording, with this host, version and (default) start time now."""
    start = start or datetime.now(UTC)
    return RecordingMetadata(
        stand_config=stand_config,
        backend=Backend(backend),
        start_time_utc=start.astimezone(UTC).isoformat(timespec="microseconds"),
        sample_rate_hz=sample_rate_hz,
        signal=signal,
        effects=effects,
        software_version=software_version(),
        host=socket.gethostname(),
        operator_note=operator_note,
        source=source,
        operator=operator,
        sample=sample,
        run_id=str(uuid.uuid4()),
        tags=tags,
    )


def as_block(block: Block, dtype: np.dtype[Any], stream: str) -> NDArray[np.void]:
    """A block as a 1-D structured array of ``dtype`` (no copy when it already is one)."""
    if isinstance(block, np.ndarray):
        if block.dtype == dtype and block.ndim == 1:
            return block
        if block.dtype.names is None or block.ndim != 1:
            raise InvalidDataError(f"{stream}: a block must be a 1-D structured array or a dict")
        fields: Mapping[str, Any] = {n: block[n] for n in block.dtype.names}
    else:
        fields = block
    names = dtype.names or ()
    missing = [n for n in names if n not in fields]
    if missing:
        raise InvalidDataError(f"{stream}: block lacks field(s) {', '.join(missing)}")
    columns = {n: np.asarray(fields[n]) for n in names}
    lengths = {c.shape for c in columns.values()}
    if len(lengths) != 1 or len(next(iter(lengths))) != 1:
        shapes = ", ".join(f"{n}{c.shape}" for n, c in columns.items())
        raise InvalidDataError(f"{stream}: block fields must be 1-D of equal length: {shapes}")
    out = np.empty(next(iter(lengths))[0], dtype=dtype)
    for n, c in columns.items():
        out[n] = c
    return out


def concat_blocks(parts: list[NDArray[np.void]]) -> NDArray[np.void]:
    """Concatenate blocks of one structured dtype as raw bytes.

    ``np.concatenate`` promotes structured dtypes field by field in Python (≈ 35 µs per
    block, measured); joining the bytes is 8× faster.
    """
    if len(parts) == 1:
        return parts[0]
    dtype = parts[0].dtype
    if dtype.hasobject:  # strings (events): no raw bytes to join
        return np.concatenate(parts)
    raw = np.concatenate([np.ascontiguousarray(p).view(np.uint8) for p in parts])
    return raw.view(dtype)


def unwrap_u16(counter: NDArray[np.integer[Any]], previous: int | None = None) -> NDArray[np.int64]:
    """Unwrap the front end's 16-bit sequence counter to int64.

    Parameters
    ----------
    counter
        Raw counter values 0..65535, shape (N,).
    previous
        The unwrapped value before this block (None at the start of a run).

    Returns
    -------
    Unwrapped counter, shape (N,): each step taken as the forward distance modulo 2¹⁶,
    so a gap (lost samples) stays visible as long as fewer than 65536 are lost at once.
    """
    raw = np.asarray(counter, dtype=np.int64)
    if raw.size == 0:
        return raw
    first = raw[0] if previous is None else previous + ((raw[0] - previous) % 65536)
    steps = np.diff(raw) % 65536
    out = np.empty_like(raw)
    out[0] = first
    np.cumsum(steps, out=out[1:])
    out[1:] += first
    return out
