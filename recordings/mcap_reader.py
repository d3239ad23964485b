"""Reading MCAP recordings: a streaming walk over the data section with CRC checks.

The walk reads records in file order and never needs the summary section, so it reads a
file whose writer was killed up to its last complete chunk (``salvage=True``), where the
``mcap`` package's seeking reader fails. Each chunk's CRC is checked after decompression.
"""

from __future__ import annotations

import logging
import struct
import zlib
from collections import defaultdict
from io import BytesIO
from pathlib import Path

import numpy as np
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import EndOfFile, McapError
from mcap.records import Channel, Chunk, Metadata, Schema
from numpy.typing import NDArray

from recordings.base import EVENTS_DTYPE
from recordings.errors import (
    CorruptRecordingError,
    MissingChannelError,
    TruncatedRecordingError,
    one_line,
)
from recordings.mcap_writer import (
    COMMAND_CODEC,
    DRIVE_CODEC,
    GAUGE_CODEC,
    METADATA_NAME,
    TOPICS,
)
from recordings.mcapcheck import MAGIC, check_layout, chunk_limit
from recordings.proto import DRIVE_STATE, EVENT, parse
from recordings.recording import Recording
from recordings.schema import DRIVE_DTYPE, RecordingMetadata

__all__ = ["check_chunks", "read_mcap"]

log = logging.getLogger(__name__)

_HEADER, _FOOTER, _SCHEMA, _CHANNEL, _MESSAGE, _CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
_MESSAGE_INDEX, _METADATA, _DATA_END = 0x07, 0x0C, 0x0F
_RECORD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")
_CHANNEL_ID = struct.Struct("<H")
REQUIRED_TOPICS = ("/gauges", "/command", "/drive", "/events")


class _Walk:
    """State of one pass over the file."""

    def __init__(self, where: str, salvage: bool) -> None:
        self.where = where
        self.salvage = salvage
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.metadata: dict[str, str] | None = None
        self.messages: dict[int, list[memoryview]] = defaultdict(list)
        self.skip: set[int] = set()
        self.repairs: list[str] = []
        self.chunks = 0
        self.truncation: str | None = None
        self._zstd = zstandard.ZstdDecompressor()

    def record(self, opcode: int, body: memoryview) -> None:
        if opcode == _CHUNK:
            self.chunk(body)
        elif opcode == _MESSAGE:
            self.message(body)
        elif opcode == _SCHEMA:
            schema = Schema.read(_stream(body))
            self.schemas[schema.id] = schema
        elif opcode == _CHANNEL:
            channel = Channel.read(_stream(body))
            self.channels[channel.id] = channel
            if channel.topic not in REQUIRED_TOPICS:
                self.skip.add(channel.id)  # e.g. /gauges/plot: derived, not read back
        elif opcode == _METADATA:
            meta = Metadata.read(_stream(body))
            if meta.name == METADATA_NAME:
                self.metadata = meta.metadata

    def message(self, body: memoryview) -> None:
        (channel_id,) = _CHANNEL_ID.unpack_from(body)
        if channel_id not in self.skip:
            self.messages[channel_id].append(body[_MESSAGE_HEAD.size :])

    def chunk(self, body: memoryview) -> None:
        chunk = Chunk.read(_stream(body))
        try:
            data = self._decompress(chunk)
        except CorruptRecordingError as err:
            if not self.salvage:
                raise
            self.repairs.append(f"dropped chunk {self.chunks + 1}: {err}")
            return
        self.chunks += 1
        view, pos, end = memoryview(data), 0, len(data)
        record_head, channel_of = _RECORD.unpack_from, _CHANNEL_ID.unpack_from
        skip, messages, data_at = self.skip, self.messages, _RECORD.size + _MESSAGE_HEAD.size
        while pos < end:  # the hot loop: one pass per message, kept lean on purpose
            opcode, length = record_head(view, pos)
            stop = pos + _RECORD.size + length
            if stop > end:
                break  # a damaged length: "ends mid-record" below
            if opcode == _MESSAGE:
                (channel_id,) = channel_of(view, pos + _RECORD.size)
                if channel_id not in skip:
                    messages[channel_id].append(view[pos + data_at : stop])
            else:
                self.record(opcode, view[pos + _RECORD.size : stop])
            pos = stop
        if pos != end:
            raise CorruptRecordingError(f"{self.where}: chunk {self.chunks} ends mid-record")

    def _decompress(self, chunk: Chunk) -> bytes:
        where = f"{self.where}: chunk {self.chunks + 1}"
        limit = chunk_limit(len(chunk.data))
        if chunk.uncompressed_size > limit:
            raise CorruptRecordingError(
                f"{where}: claims {chunk.uncompressed_size} bytes uncompressed from "
                f"{len(chunk.data)} compressed (at most {limit})"
            )
        try:
            if chunk.compression == "zstd":
                data = self._zstd.decompress(chunk.data, max_output_size=chunk.uncompressed_size)
            elif chunk.compression == "lz4":
                import lz4.frame  # type: ignore[import-untyped]

                data = lz4.frame.decompress(chunk.data)
            elif chunk.compression == "":
                data = chunk.data
            else:
                raise CorruptRecordingError(f"{where}: unknown compression {chunk.compression!r}")
        except (zstandard.ZstdError, RuntimeError) as err:  # lz4 raises RuntimeError
            raise CorruptRecordingError(
                f"{where}: does not decompress: {one_line(str(err))}"
            ) from err
        if len(data) != chunk.uncompressed_size:
            raise CorruptRecordingError(
                f"{where}: {len(data)} bytes, the header says {chunk.uncompressed_size}"
            )
        crc = zlib.crc32(data)
        if chunk.uncompressed_crc not in {0, crc}:
            raise CorruptRecordingError(
                f"{where}: CRC {crc:#010x} does not match {chunk.uncompressed_crc:#010x}"
            )
        return data


def _stream(body: memoryview) -> ReadDataStream:
    return ReadDataStream(BytesIO(body))


def _walk_file(path: Path, salvage: bool) -> _Walk:
    where = str(path)
    data = path.read_bytes()
    if data[:8] != MAGIC:
        raise CorruptRecordingError(f"{where}: not an MCAP file (no MCAP magic at the start)")
    walk = _Walk(where, salvage)
    try:  # the layout check every read path runs; a salvage rebuilds the summary instead
        check_layout(data, where)
    except CorruptRecordingError as err:
        if not salvage or "summary section is damaged" not in str(err):
            raise
        walk.repairs.append("the summary section was damaged: rebuilt from the data")
    view, pos, size = memoryview(data), len(MAGIC), len(data)
    ended = False
    while pos < size:
        if pos + _RECORD.size > size:
            break
        opcode, length = _RECORD.unpack_from(view, pos)
        if pos + _RECORD.size + length > size:
            break
        body = view[pos + _RECORD.size : pos + _RECORD.size + length]
        if opcode == _CHUNK and _only_skipped_channels(view, pos + _RECORD.size + length, walk):
            walk.chunks += 1  # e.g. the /gauges/plot chunks: not needed, not decompressed
            pos += _RECORD.size + length
            continue
        _decode(walk, opcode, body, pos)
        pos += _RECORD.size + length
        if opcode == _DATA_END:
            ended = True
            break
    intact = ended and data[-8:] == MAGIC
    if not intact:
        _truncated(walk, pos, size, ended)
    return walk


def _decode(walk: _Walk, opcode: int, body: memoryview, pos: int) -> None:
    """One top-level record into the walk; what does not decode, as CorruptRecordingError."""
    try:
        walk.record(opcode, body)
    # OverflowError: a length field near 2**64 handed to BytesIO.read or a slice
    except (struct.error, ValueError, UnicodeDecodeError, McapError, OverflowError) as err:
        if isinstance(err, CorruptRecordingError):
            raise
        if isinstance(err, EndOfFile):
            detail = "it ends before its fields do"
        elif isinstance(err, OverflowError):
            detail = "a length field in it is larger than any file"
        else:
            detail = one_line(str(err))
        raise CorruptRecordingError(
            f"{walk.where}: record {opcode:#04x} at byte {pos} does not decode: {detail}"
        ) from err


def check_chunks(chunks: list[tuple[int, bytes]], where: str) -> dict[int, Channel]:
    """The whole read's checks of chunk records (offset in the file, the record's bytes).

    Decompression, CRC and inner records, for the window reader, which hands those chunks
    to the ``mcap`` package's reader (it checks less). Returns the channels the chunks
    define, for the caller to hold against the summary's.
    """
    walk = _Walk(where, salvage=False)
    for offset, record in chunks:
        _decode(walk, _CHUNK, memoryview(record)[_RECORD.size :], offset)
    return walk.channels


def _only_skipped_channels(view: memoryview, pos: int, walk: _Walk) -> bool:
    """Whether the message indexes after a chunk name only channels the reader skips."""
    channels: set[int] = set()
    while pos + _RECORD.size + 2 <= len(view):
        opcode, length = _RECORD.unpack_from(view, pos)
        if opcode != _MESSAGE_INDEX:
            break
        channels.add(_CHANNEL_ID.unpack_from(view, pos + _RECORD.size)[0])
        pos += _RECORD.size + length
    return bool(channels) and channels <= walk.skip


def _truncated(walk: _Walk, pos: int, size: int, ended: bool) -> None:
    what = "its summary" if ended else f"at byte {pos} of {size} inside the data"
    walk.truncation = (
        f"the file is truncated ({what}; its writer was killed?): {walk.chunks} complete chunk(s)"
    )


def _topic_ids(walk: _Walk) -> dict[str, int]:
    ids = {c.topic: c.id for c in walk.channels.values()}
    for topic in REQUIRED_TOPICS:
        if topic not in ids:
            raise MissingChannelError(f"{walk.where}: no channel {topic!r} in the file")
        channel = walk.channels[ids[topic]]
        schema = walk.schemas.get(channel.schema_id)
        if schema is None or schema.name != TOPICS[topic] or channel.message_encoding != "protobuf":
            got = schema.name if schema else "no schema"
            raise CorruptRecordingError(
                f"{walk.where}: channel {topic!r} carries {got} ({channel.message_encoding}), "
                f"expected {TOPICS[topic]} (protobuf)"
            )
    return ids


def _drive(walk: _Walk, messages: list[memoryview]) -> NDArray[np.void]:
    out = np.empty(len(messages), dtype=DRIVE_DTYPE)
    fast = DRIVE_CODEC.decode_fast(messages)
    if fast is not None:
        for name in DRIVE_DTYPE.names or ():
            out[name] = fast[name]
        return out
    for i, data in enumerate(messages):  # any other valid encoding: the protobuf runtime
        msg = parse(DRIVE_STATE, bytes(data), walk.where)
        out[i] = (
            msg.t_ns,
            msg.position_mm,
            msg.speed_mm_s,
            msg.status_word,
            msg.trip_code,
            msg.enabled,
        )
    return out


def _events(walk: _Walk, messages: list[memoryview]) -> NDArray[np.void]:
    out = np.empty(len(messages), dtype=EVENTS_DTYPE)
    for i, data in enumerate(messages):
        msg = parse(EVENT, bytes(data), walk.where)
        out[i] = (msg.t_ns, msg.kind, msg.text)
    return out


def read_mcap(path: Path, *, salvage: bool = False) -> Recording:
    """Read an MCAP recording (see ``open_recording``)."""
    walk = _walk_file(path, salvage)
    if walk.metadata is None:
        raise MissingChannelError(f"{path}: no {METADATA_NAME!r} metadata record")
    if "json" not in walk.metadata:
        raise MissingChannelError(f"{path}: metadata record {METADATA_NAME!r} lacks 'json'")
    metadata = RecordingMetadata.from_json(walk.metadata["json"], str(path))
    ids = _topic_ids(walk)
    where = str(path)
    gauges = GAUGE_CODEC.decode_many(walk.messages.get(ids["/gauges"], []), where)
    command = COMMAND_CODEC.decode_many(walk.messages.get(ids["/command"], []), where)
    drive = _drive(walk, walk.messages.get(ids["/drive"], []))
    events = _events(walk, walk.messages.get(ids["/events"], []))
    if walk.truncation is not None:
        end_s = gauges["t_ns"][-1] / 1e9 if len(gauges) else 0.0
        line = f"{walk.truncation}, data up to t = {end_s:.4f} s"
        if not salvage:
            raise TruncatedRecordingError(
                f"{where}: {line}; run `labstand recover {where} -o FIXED.mcap`"
            )
        walk.repairs.append(f"recovered: {line}")
    return Recording(
        path=path,
        metadata=metadata,
        gauges=gauges,
        command=command,
        drive=drive,
        events_array=events,
        repairs=walk.repairs,
    )
