"""The protobuf messages of the MCAP format, and a numpy codec for the batched ones.

The schema (package ``labstand.recording.v1``) is built here as a FileDescriptorSet, the
form MCAP's protobuf profile stores and Foxglove decodes. The batch messages hold packed
repeated fixed-width fields only (``sfixed64``, ``double``, ``fixed32``), whose wire
bytes are the little-endian arrays themselves: encoding is ``ndarray.tobytes()`` behind
a tag and a length, decoding is ``np.frombuffer``, and the ``protobuf`` runtime is only
used for the low-rate messages (and by the tests, as an independent decoder).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf.message import DecodeError, Message
from numpy.typing import NDArray

from recordings.errors import CorruptRecordingError

__all__ = [
    "COMMAND_BATCH",
    "DERIVED",
    "DRIVE_STATE",
    "EVENT",
    "GAUGE_BATCH",
    "GAUGE_SAMPLE",
    "PACKAGE",
    "BatchCodec",
    "FixedCodec",
    "file_descriptor_set",
    "message_class",
]

PACKAGE = "labstand.recording.v1"
GAUGE_BATCH = f"{PACKAGE}.GaugeBatch"
COMMAND_BATCH = f"{PACKAGE}.CommandBatch"
GAUGE_SAMPLE = f"{PACKAGE}.GaugeSample"
DRIVE_STATE = f"{PACKAGE}.DriveState"
EVENT = f"{PACKAGE}.Event"

_F = descriptor_pb2.FieldDescriptorProto
_TYPES = {
    "sfixed64": _F.TYPE_SFIXED64,
    "double": _F.TYPE_DOUBLE,
    "fixed32": _F.TYPE_FIXED32,
    "uint32": _F.TYPE_UINT32,
    "bool": _F.TYPE_BOOL,
    "string": _F.TYPE_STRING,
}
# message name -> (field name, proto type, repeated)
_MESSAGES: dict[str, list[tuple[str, str, bool]]] = {
    "GaugeBatch": [
        ("seq", "sfixed64", True),
        ("t_ns", "sfixed64", True),
        ("x_mm", "double", True),
        ("u_mm", "double", True),
        ("force_n", "double", True),
        ("flags", "fixed32", True),
        ("t_s", "double", True),  # derived: t_ns / 1e9, for Foxglove's plot (§2)
    ],
    "CommandBatch": [
        ("t_ns", "sfixed64", True),
        ("x_cmd_mm", "double", True),
        ("t_s", "double", True),  # derived, as in GaugeBatch
    ],
    "GaugeSample": [
        ("seq", "sfixed64", False),
        ("t_ns", "sfixed64", False),
        ("x_mm", "double", False),
        ("u_mm", "double", False),
        ("force_n", "double", False),
    ],
    "DriveState": [
        ("t_ns", "sfixed64", False),
        ("position_mm", "double", False),
        ("speed_mm_s", "double", False),
        ("status_word", "fixed32", False),
        ("trip_code", "fixed32", False),
        ("enabled", "bool", False),
    ],
    "Event": [("t_ns", "sfixed64", False), ("kind", "string", False), ("text", "string", False)],
}
_WIRE_DTYPES = {"sfixed64": "<i8", "double": "<f8", "fixed32": "<u4", "bool": "u1"}
_WIRE_TYPES = {"sfixed64": 1, "double": 1, "fixed32": 5, "bool": 0}


def _file_proto() -> descriptor_pb2.FileDescriptorProto:
    proto = descriptor_pb2.FileDescriptorProto(
        name="labstand/recording/v1/recording.proto", package=PACKAGE, syntax="proto3"
    )
    for name, fields in _MESSAGES.items():
        msg = proto.message_type.add(name=name)
        for number, (fname, ftype, repeated) in enumerate(fields, start=1):
            msg.field.add(
                name=fname,
                number=number,
                type=_TYPES[ftype],
                label=_F.LABEL_REPEATED if repeated else _F.LABEL_OPTIONAL,
                json_name=fname,
            )
    return proto


_FILE = _file_proto()
_POOL = descriptor_pool.DescriptorPool()
_POOL.Add(_FILE)


def file_descriptor_set() -> bytes:
    """The serialized FileDescriptorSet every protobuf schema record of the file carries."""
    return descriptor_pb2.FileDescriptorSet(file=[_FILE]).SerializeToString()


def message_class(full_name: str) -> type[Message]:
    """The protobuf runtime class of one of our messages."""
    return message_factory.GetMessageClass(_POOL.FindMessageTypeByName(full_name))


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        bits = value & 0x7F
        value >>= 7
        if value:
            out.append(bits | 0x80)
        else:
            out.append(bits)
            return bytes(out)


#: Batch fields computed from others when writing, never read back.
DERIVED = {"t_s": "t_ns"}


class BatchCodec:
    """Encode/decode one batch message from/to a structured array with matching fields.

    Parameters
    ----------
    name
        Message name in ``_MESSAGES`` (``GaugeBatch`` or ``CommandBatch``).
    dtype
        The stream's numpy dtype; every message field must be one of its fields, but
        the derived ``t_s`` (``t_ns`` in s), which is written, and skipped when read.
    derived
        Write the derived fields (False: the layout before they existed, for the
        benchmark and the compatibility tests).
    """

    def __init__(self, name: str, dtype: np.dtype[Any], derived: bool = True) -> None:
        self.name = f"{PACKAGE}.{name}"
        self.dtype = dtype
        spec = _MESSAGES[name]
        fields = [(f, n, np.dtype(_WIRE_DTYPES[t])) for n, (f, t, _) in enumerate(spec, 1)]
        self._fields = [f for f in fields if f[0] not in DERIVED]
        self._derived = [f for f in fields if f[0] in DERIVED] if derived else []
        self._numbers = {n: (f, wire) for f, n, wire in self._fields}

    def encode(self, block: NDArray[np.void]) -> bytes:
        """One message holding every sample of ``block``."""
        parts: list[bytes] = []
        if len(block) == 0:
            return b""
        for fname, number, wire in self._fields:
            raw = np.ascontiguousarray(block[fname], dtype=wire).tobytes()
            parts += [_varint(number << 3 | 2), _varint(len(raw)), raw]
        for fname, number, wire in self._derived:  # t_s = t_ns / 1e9
            raw = (block[DERIVED[fname]] / 1e9).astype(wire).tobytes()
            parts += [_varint(number << 3 | 2), _varint(len(raw)), raw]
        return b"".join(parts)

    def decode_many(self, messages: Sequence[memoryview | bytes], where: str) -> NDArray[np.void]:
        """Concatenate many messages into one structured array.

        Accepts packed and unpacked repeated encodings; skips unknown fields.
        """
        pieces: dict[str, list[memoryview | bytes]] = {f: [] for f, _, _ in self._fields}
        for index, data in enumerate(messages):
            counts = self._split(memoryview(data), pieces, where, index)
            if len(set(counts)) > 1:
                raise CorruptRecordingError(
                    f"{where}: {self.name} message {index} has fields of unequal lengths {counts}"
                )
        size = None
        columns: dict[str, NDArray[Any]] = {}
        for fname, _, wire in self._fields:
            columns[fname] = np.frombuffer(b"".join(pieces[fname]), dtype=wire)
            size = len(columns[fname]) if size is None else size
        out = np.empty(size or 0, dtype=self.dtype)
        for fname, col in columns.items():
            out[fname] = col
        return out

    def _split(
        self,
        data: memoryview,
        pieces: dict[str, list[memoryview | bytes]],
        where: str,
        index: int,
    ) -> list[int]:
        pos, end = 0, len(data)
        counts = dict.fromkeys(pieces, 0)
        try:
            while pos < end:
                tag, pos = _read_varint(data, pos)
                number, wire_type = tag >> 3, tag & 7
                if wire_type == 2:
                    length, pos = _read_varint(data, pos)
                elif wire_type in {1, 5}:
                    length = 8 if wire_type == 1 else 4
                elif wire_type == 0:
                    _, pos = _read_varint(data, pos)
                    continue
                else:
                    raise CorruptRecordingError(f"wire type {wire_type}")
                if pos + length > end:
                    raise CorruptRecordingError("field runs past the end")
                if number in self._numbers:
                    fname, wire = self._numbers[number]
                    if length % wire.itemsize:
                        raise CorruptRecordingError(f"field {fname} is {length} bytes")
                    pieces[fname].append(data[pos : pos + length])
                    counts[fname] += length // wire.itemsize
                pos += length
        except (CorruptRecordingError, IndexError) as err:
            raise CorruptRecordingError(
                f"{where}: {self.name} message {index} does not decode: {err}"
            ) from err
        return list(counts.values())


def _read_varint(data: memoryview, pos: int) -> tuple[int, int]:
    result = shift = 0
    while True:
        byte = data[pos]
        pos += 1
        result |= (byte & 0x7F) << shift
        if not byte & 0x80:
            return result, pos
        shift += 7
        if shift > 63:
            raise CorruptRecordingError("varint too long")


def parse(full_name: str, data: bytes, where: str) -> Any:
    """Decode one low-rate message with the protobuf runtime."""
    msg = message_class(full_name)()
    try:
        msg.ParseFromString(data)
    except DecodeError as err:
        raise CorruptRecordingError(f"{where}: a {full_name} message does not decode") from err
    return msg


class FixedCodec:
    """One message per row, every field present, in field order: a fixed byte layout.

    For messages of scalar fixed-width fields (and bools, one-byte varints), each row
    encodes to the same bytes a protobuf runtime would accept, so a block is encoded by
    one numpy copy, and messages of exactly that layout decode by one ``frombuffer``
    (others fall back to the protobuf runtime, as any valid encoding must be read).
    """

    def __init__(self, name: str) -> None:
        self.name = f"{PACKAGE}.{name}"
        fields: list[tuple[str, str]] = []
        self._tags: dict[str, int] = {}
        for number, (fname, ftype, repeated) in enumerate(_MESSAGES[name], start=1):
            assert not repeated and ftype in _WIRE_TYPES
            fields += [(f"_k{number}", "u1"), (fname, _WIRE_DTYPES[ftype])]
            self._tags[f"_k{number}"] = number << 3 | _WIRE_TYPES[ftype]
        self.wire = np.dtype(fields)
        self.names = [f for f, _, _ in _MESSAGES[name]]

    def encode(self, rows: NDArray[np.void]) -> list[bytes]:
        """One message per row of ``rows`` (a structured array with our field names)."""
        wire = np.empty(len(rows), dtype=self.wire)
        for key, tag in self._tags.items():
            wire[key] = tag
        for fname in self.names:
            wire[fname] = rows[fname]
        raw, size = wire.tobytes(), self.wire.itemsize
        return [raw[i * size : (i + 1) * size] for i in range(len(rows))]

    def decode_fast(self, messages: Sequence[memoryview | bytes]) -> NDArray[np.void] | None:
        """All messages as one array, or None when any is not in the fixed layout."""
        size = self.wire.itemsize
        if any(len(m) != size for m in messages):
            return None
        wire = np.frombuffer(b"".join(messages), dtype=self.wire)
        for key, tag in self._tags.items():
            if not np.all(wire[key] == tag):
                return None
        if "enabled" in self.names and np.any(wire["enabled"] > 1):
            return None
        return wire
