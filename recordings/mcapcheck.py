"""The one layout check of an MCAP recording, before any reader trusts a length in it.

Both read paths run it: the whole-file walk (``recordings.mcap_reader``) and the window
reader (``recordings.window``), which hands the file to the ``mcap`` package's seeking
reader. That reader believes the footer, the summary and the chunk index: a length taken
from garbage is ``read()`` (gigabytes), an offset past the end is a failed ``seek``, a
size near 2⁶⁴ an ``OverflowError``. So the check walks every top-level record's framing
(no decompression: a few hundred records), reads each chunk's header fields, and, for a
file that ends with its footer, demands a summary that agrees with the data: every chunk
index names a chunk that is there, with its offset, length, sizes and times, and every
chunk is indexed once; every metadata index points at a metadata record.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

from recordings.errors import CorruptRecordingError

__all__ = ["MAGIC", "MAX_CHUNK_BYTES", "McapLayout", "check_layout", "chunk_limit"]

MAGIC = b"\x89MCAP0\r\n"
_FOOTER, _CHUNK, _CHUNK_INDEX, _METADATA, _METADATA_INDEX, _DATA_END = (
    0x02,
    0x06,
    0x08,
    0x0C,
    0x0D,
    0x0F,
)
_RECORD = struct.Struct("<BQ")
_CHUNK_HEAD = struct.Struct("<QQQI")  # start time, end time, uncompressed size, CRC
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_FOOTER_BODY = struct.Struct("<QQI")
#: A chunk may claim at most this much uncompressed data per compressed byte (zstd and lz4
#: reach a few hundred on real data); a bit flip in the size field then cannot allocate GBs.
MAX_CHUNK_RATIO = 1024
MAX_CHUNK_BYTES = 2**30


def chunk_limit(compressed: int) -> int:
    """The most bytes a chunk of ``compressed`` bytes may claim uncompressed."""
    return min(MAX_CHUNK_RATIO * compressed + 2**16, MAX_CHUNK_BYTES)


@dataclass(frozen=True)
class ChunkHead:
    """A chunk record's place and header fields."""

    offset: int  # of its opcode
    length: int  # of the whole record, opcode and length included
    start_ns: int
    end_ns: int
    uncompressed_size: int
    compression: str
    compressed_size: int


@dataclass
class McapLayout:
    """What the framing walk found. ``intact``: DataEnd, a footer and a summary that agrees."""

    chunks: list[ChunkHead] = field(default_factory=list)
    metadata_offsets: set[int] = field(default_factory=set)
    data_end: int | None = None
    intact: bool = False
    problem: str = ""  # why not intact (a truncated data section, no summary, ...)


def _chunk_head(data: bytes, pos: int, length: int, where: str) -> ChunkHead:
    body, end = pos + _RECORD.size, pos + _RECORD.size + length
    fail = CorruptRecordingError(
        f"{where}: record {_CHUNK:#04x} at byte {pos} does not decode: it ends before its fields do"
    )
    if body + _CHUNK_HEAD.size + _U32.size > end:
        raise fail
    start_ns, end_ns, size, _ = _CHUNK_HEAD.unpack_from(data, body)
    at = body + _CHUNK_HEAD.size
    (text_len,) = _U32.unpack_from(data, at)
    at += _U32.size + text_len
    if at + _U64.size > end:
        raise fail
    compression = bytes(data[at - text_len : at]).decode("utf-8", "replace")
    (records_len,) = _U64.unpack_from(data, at)
    if at + _U64.size + records_len != end:
        raise fail
    return ChunkHead(pos, _RECORD.size + length, start_ns, end_ns, size, compression, records_len)


def check_layout(data: bytes, where: str) -> McapLayout:
    """Walk the framing of ``data`` (a whole MCAP file); raise CorruptRecordingError.

    Raises for what no reader can get past: no magic, a chunk whose header fields do not
    fit its record, a chunk claiming more than ``chunk_limit`` uncompressed, a footer or
    summary that disagrees with the data. A data section that ends mid-record (a killed
    writer) is not raised: ``intact`` is False and ``problem`` says why, for the caller
    (the walk salvages it; the window reader leaves it to the walk).
    """
    if bytes(data[:8]) != MAGIC:
        raise CorruptRecordingError(f"{where}: not an MCAP file (no MCAP magic at the start)")
    layout = McapLayout()
    pos, size = len(MAGIC), len(data)
    while pos + _RECORD.size <= size:
        opcode, length = _RECORD.unpack_from(data, pos)
        if pos + _RECORD.size + length > size:
            break
        if opcode == _CHUNK:
            head = _chunk_head(data, pos, length, where)
            if head.uncompressed_size > chunk_limit(head.compressed_size):
                raise CorruptRecordingError(
                    f"{where}: chunk {len(layout.chunks) + 1}: claims "
                    f"{head.uncompressed_size} bytes uncompressed from "
                    f"{head.compressed_size} compressed "
                    f"(at most {chunk_limit(head.compressed_size)})"
                )
            layout.chunks.append(head)
        elif opcode == _METADATA:
            layout.metadata_offsets.add(pos)
        pos += _RECORD.size + length
        if opcode == _DATA_END:
            layout.data_end = pos
            break
    if layout.data_end is None:
        layout.problem = f"the data section ends mid-record at byte {pos} of {size}"
        return layout
    if bytes(data[-8:]) != MAGIC or size < pos + _RECORD.size + _FOOTER_BODY.size + 8:
        layout.problem = "the file ends inside its summary or footer"
        return layout
    _check_summary(data, layout, where)
    layout.intact = True
    return layout


def _check_summary(data: bytes, layout: McapLayout, where: str) -> None:
    size = len(data)
    footer = size - 8 - _RECORD.size - _FOOTER_BODY.size
    opcode, length = _RECORD.unpack_from(data, footer)
    if opcode != _FOOTER or length != _FOOTER_BODY.size:
        raise _summary_error(where, f"no footer record before the closing magic (byte {footer})")
    assert layout.data_end is not None
    summary_start, offsets_start, _ = _FOOTER_BODY.unpack_from(data, footer + _RECORD.size)
    if summary_start == 0:
        return  # a file without a summary: legal; the seeking reader will not be used
    if not layout.data_end <= summary_start <= footer:
        raise _summary_error(where, f"the footer puts the summary at byte {summary_start}")
    if offsets_start and not summary_start <= offsets_start <= footer:
        raise _summary_error(where, f"the footer puts its offsets at byte {offsets_start}")
    chunks = {c.offset: c for c in layout.chunks}
    indexed: set[int] = set()
    pos = summary_start
    while pos < footer:
        if pos + _RECORD.size > footer:
            raise _summary_error(where, f"a record at byte {pos} is cut by the footer")
        opcode, length = _RECORD.unpack_from(data, pos)
        body = pos + _RECORD.size
        if body + length > footer:
            raise _summary_error(where, f"record {opcode:#04x} at byte {pos} runs into the footer")
        if opcode == _CHUNK_INDEX:
            offset = _chunk_index(data, body, length, chunks, where, pos)
            if offset in indexed:
                raise _summary_error(where, f"chunk at byte {offset} is indexed twice")
            indexed.add(offset)
        elif opcode == _METADATA_INDEX:
            if length < 16:
                raise _summary_error(where, f"metadata index at byte {pos} is cut short")
            offset, record_len = struct.unpack_from("<QQ", data, body)
            if offset not in layout.metadata_offsets or record_len > size - offset:
                raise _summary_error(where, f"metadata index at byte {pos} points at {offset}")
        pos = body + length
    if indexed and indexed != set(chunks):
        raise _summary_error(where, f"{len(set(chunks) - indexed)} chunk(s) are not indexed")


def _chunk_index(
    data: bytes, body: int, length: int, chunks: dict[int, ChunkHead], where: str, pos: int
) -> int:
    """Check one chunk index record against the chunk it names; its offset."""
    end = body + length
    if body + 36 > end:
        raise _summary_error(where, f"chunk index at byte {pos} is cut short")
    start_ns, end_ns, offset, chunk_len, map_len = struct.unpack_from("<QQQQI", data, body)
    at = body + 36 + map_len
    if at + 12 > end:
        raise _summary_error(where, f"chunk index at byte {pos} is cut short")
    (text_len,) = _U32.unpack_from(data, at + 8)
    at += 12 + text_len
    if at + 16 != end:
        raise _summary_error(where, f"chunk index at byte {pos} does not decode")
    compressed, uncompressed = struct.unpack_from("<QQ", data, at)
    chunk = chunks.get(offset)
    if chunk is None:
        raise _summary_error(where, f"chunk index at byte {pos} points at byte {offset}: no chunk")
    found = (chunk.length, chunk.start_ns, chunk.end_ns, chunk.compressed_size)
    if (
        chunk_len,
        start_ns,
        end_ns,
        compressed,
    ) != found or uncompressed != chunk.uncompressed_size:
        raise _summary_error(
            where, f"chunk index at byte {pos} disagrees with the chunk at byte {offset}"
        )
    return int(offset)


def _summary_error(where: str, detail: str) -> CorruptRecordingError:
    return CorruptRecordingError(
        f"{where}: the summary section is damaged: {detail}; "
        f"`labstand recover {where} -o FIXED.mcap` rebuilds it from the data"
    )
