"""Writing recordings as MCAP: protobuf messages, zstd chunks, a chunk per flush.

Topics (docs/recording-format.md):

========================  ==========================  ======================================
topic                     message                     rate
========================  ==========================  ======================================
``/gauges``               ``GaugeBatch``              batches of ≤ ``batch_samples`` samples,
                                                      each with its time in s (``t_s``)
``/command``              ``CommandBatch``            batches, as ``/gauges``
``/gauges/plot``          ``GaugeSample``             one sample per message, decimated to
                                                      ``plot_rate_hz`` (for Foxglove's plot)
``/drive``                ``DriveState``              one per poll
``/events``               ``Event``                   one per event
========================  ==========================  ======================================

Every message's log time is the run's start (Unix ns) plus the sample's ``t_ns`` (the
first sample's for a batch), so Foxglove shows wall-clock time; ``t_ns`` in the payload
is the authority. Metadata record ``labstand.recording`` holds the schema version and
the metadata as JSON; attachment ``stand.json`` holds the stand configuration.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from mcap.writer import CompressionType, Writer
from numpy.typing import NDArray

from recordings.base import RecordingWriter
from recordings.errors import InvalidDataError
from recordings.proto import (
    DRIVE_STATE,
    EVENT,
    GAUGE_SAMPLE,
    BatchCodec,
    FixedCodec,
    file_descriptor_set,
    message_class,
)
from recordings.schema import (
    COMMAND_DTYPE,
    GAUGES_DTYPE,
    MAX_TIME_NS,
    SCHEMA_VERSION,
    UNITS,
    RecordingMetadata,
    concat_blocks,
    software_version,
)

__all__ = ["METADATA_NAME", "TOPICS", "McapRecordingWriter"]

log = logging.getLogger(__name__)

METADATA_NAME = "labstand.recording"
#: topic -> protobuf message name
TOPICS = {
    "/gauges": "labstand.recording.v1.GaugeBatch",
    "/command": "labstand.recording.v1.CommandBatch",
    "/gauges/plot": GAUGE_SAMPLE,
    "/drive": DRIVE_STATE,
    "/events": EVENT,
}
GAUGE_CODEC = BatchCodec("GaugeBatch", GAUGES_DTYPE)
COMMAND_CODEC = BatchCodec("CommandBatch", COMMAND_DTYPE)
#: The batches as written before the derived per-sample ``t_s`` (time_s=False).
_PLAIN_CODECS = (
    BatchCodec("GaugeBatch", GAUGES_DTYPE, derived=False),
    BatchCodec("CommandBatch", COMMAND_DTYPE, derived=False),
)

PLOT_CODEC = FixedCodec("GaugeSample")
DRIVE_CODEC = FixedCodec("DriveState")


class _Batcher:
    """Collects blocks until a message's worth of samples is there."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.parts: list[NDArray[np.void]] = []
        self.count = 0

    def add(self, block: NDArray[np.void]) -> list[NDArray[np.void]]:
        """Append; return the full batches ready to be written."""
        self.parts.append(block)
        self.count += len(block)
        if self.count < self.size:
            return []
        return self.take(whole_only=True)

    def take(self, whole_only: bool = False) -> list[NDArray[np.void]]:
        """Every full batch (and the remainder, unless ``whole_only``)."""
        if not self.parts:
            return []
        data = concat_blocks(self.parts)
        cut = (len(data) // self.size) * self.size if whole_only else len(data)
        out = [data[i : min(i + self.size, cut)] for i in range(0, cut, self.size)]
        rest = data[cut:]
        self.parts = [rest] if len(rest) else []
        self.count = len(rest)
        return out


class McapRecordingWriter(RecordingWriter):
    """Streams a recording into an MCAP file.

    Parameters
    ----------
    path, metadata, flush_interval_s
        See ``RecordingWriter``. Each flush closes the current zstd chunk.
    batch_samples
        Samples per ``/gauges`` and ``/command`` message.
    plot_rate_hz
        Rate of the decimated ``/gauges/plot`` channel, Hz; 0 leaves it out.
    time_s
        Give every batched sample its time in s (``t_s``), so Foxglove's Plot panel
        draws the batches at full rate (x-axis "Message path" ``/gauges.t_s[:]``);
        False writes the layout before it (readers need neither).
    """

    def __init__(
        self,
        path: Path,
        metadata: RecordingMetadata,
        flush_interval_s: float = 0.5,
        batch_samples: int = 1000,
        plot_rate_hz: float = 100.0,
        time_s: bool = True,
    ) -> None:
        super().__init__(path, metadata, flush_interval_s)
        self._gauge_codec, self._command_codec = (
            (GAUGE_CODEC, COMMAND_CODEC) if time_s else _PLAIN_CODECS
        )
        self._start_ns = metadata.start_time_ns
        if not 0 <= self._start_ns <= MAX_TIME_NS:  # MCAP log times: unsigned ns since 1970
            raise InvalidDataError(
                f"{path}: cannot write MCAP: start time {metadata.start_time_utc} is outside "
                "1970 … 2255 (MCAP log times count nanoseconds from 1970)"
            )
        self._file: BinaryIO = open(self.path, "wb")  # noqa: SIM115 (closed in _close)
        self._writer = Writer(self._file, chunk_size=8 * 2**20, compression=CompressionType.ZSTD)
        self._writer.start(profile="", library=f"labstand {software_version()}")
        self._writer.add_metadata(
            METADATA_NAME,
            {
                "schema_version": str(SCHEMA_VERSION),
                "json": metadata.to_json(),
                "backend": str(metadata.backend),
                "start_time_utc": metadata.start_time_utc,
                "host": metadata.host,
                "software_version": metadata.software_version,
                "operator_note": metadata.operator_note,
            },
        )
        config = json.dumps(dict(metadata.stand_config), indent=1).encode()
        self._writer.add_attachment(
            self._start_ns, self._start_ns, "stand.json", "application/json", config
        )
        step = round(metadata.sample_rate_hz / plot_rate_hz) if plot_rate_hz > 0 else 0
        self._plot_step = max(step, 1) if plot_rate_hz > 0 else 0
        self._plot_phase = 0
        self._plot_pending: list[NDArray[np.void]] = []
        self._channels = self._register(metadata)
        self._gauges = _Batcher(batch_samples)
        self._command = _Batcher(batch_samples)
        self._event_cls = message_class(EVENT)
        self._file.flush()

    def _register(self, metadata: RecordingMetadata) -> dict[str, int]:
        fds = file_descriptor_set()
        schema_ids: dict[str, int] = {}
        channels: dict[str, int] = {}
        for topic, message in TOPICS.items():
            if topic == "/gauges/plot" and not self._plot_step:
                continue
            if message not in schema_ids:
                schema_ids[message] = self._writer.register_schema(message, "protobuf", fds)
            stream = topic.strip("/").split("/")[0]
            fields = {
                "gauges": GAUGES_DTYPE.names,
                "command": COMMAND_DTYPE.names,
            }.get(stream) or ()
            rate = metadata.sample_rate_hz if stream in {"gauges", "command"} else 0.0
            if topic == "/gauges/plot":
                rate = metadata.sample_rate_hz / self._plot_step
            channels[topic] = self._writer.register_channel(
                topic,
                "protobuf",
                schema_ids[message],
                {
                    "rate_hz": f"{rate:g}",
                    "units": json.dumps({f: UNITS[f] for f in fields}),
                    "schema_version": str(SCHEMA_VERSION),
                },
            )
        return channels

    def _log_time(self, t_ns: int) -> int:
        return max(self._start_ns + t_ns, 0)

    def _emit(self, topic: str, codec: BatchCodec, batches: list[NDArray[np.void]]) -> None:
        channel = self._channels[topic]
        for batch in batches:
            log_time = self._log_time(int(batch["t_ns"][0]))
            self._writer.add_message(channel, log_time, codec.encode(batch), log_time)

    def _write_gauges(self, block: NDArray[np.void]) -> None:
        self._emit("/gauges", self._gauge_codec, self._gauges.add(block))
        if self._plot_step:
            self._write_plot(block)

    def _write_plot(self, block: NDArray[np.void]) -> None:
        first = (-self._plot_phase) % self._plot_step
        picked = block[first :: self._plot_step]
        self._plot_phase = (self._plot_phase + len(block)) % self._plot_step
        if len(picked):
            self._plot_pending.append(picked)

    def _emit_plot(self) -> None:
        """The plot samples since the last flush, in a chunk of their own (readers skip it)."""
        if not self._plot_pending:
            return
        picked = concat_blocks(self._plot_pending)
        self._plot_pending = []
        channel, add = self._channels["/gauges/plot"], self._writer.add_message
        times = (self._start_ns + picked["t_ns"]).tolist()
        for log_time, data in zip(times, PLOT_CODEC.encode(picked), strict=True):
            add(channel, log_time, data, log_time)
        self._writer.flush()  # type: ignore[no-untyped-call]

    def _write_command(self, block: NDArray[np.void]) -> None:
        self._emit("/command", self._command_codec, self._command.add(block))

    def _write_drive(self, block: NDArray[np.void]) -> None:
        channel = self._channels["/drive"]
        times = (self._start_ns + block["t_ns"]).tolist()
        for log_time, data in zip(times, DRIVE_CODEC.encode(block), strict=True):
            self._writer.add_message(channel, max(log_time, 0), data, max(log_time, 0))

    def _write_event(self, t_ns: int, kind: str, text: str) -> None:
        msg: Any = self._event_cls(t_ns=t_ns, kind=kind, text=text)
        log_time = self._log_time(t_ns)
        self._writer.add_message(
            self._channels["/events"], log_time, msg.SerializeToString(), log_time
        )

    def _flush(self) -> None:
        self._emit("/gauges", self._gauge_codec, self._gauges.take())
        self._emit("/command", self._command_codec, self._command.take())
        # closes the chunk, writes it and its message index, flushes the file
        self._writer.flush()  # type: ignore[no-untyped-call]
        self._emit_plot()

    def _close(self) -> None:
        try:
            self._emit("/gauges", self._gauge_codec, self._gauges.take())
            self._emit("/command", self._command_codec, self._command.take())
            self._writer.flush()  # type: ignore[no-untyped-call]
            self._emit_plot()
            self._writer.finish()  # type: ignore[no-untyped-call]
        finally:
            self._file.close()
