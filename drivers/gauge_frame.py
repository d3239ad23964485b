"""The gauge front end's binary frame, and a vectorised parser for a stream of them.

Frame, 24 bytes, little-endian::

    offset size  field
     0     2     sync            A5 5A
     2     1     version         FRAME_VERSION
     3     2     sequence        u16, +1 per frame, wraps
     5     4     device time     u32, µs of the front end's clock, wraps (71.6 min)
     9     4     force           i32, counts of the force gauge
    13     4     weight position i32, counts of the displacement gauge (u)
    17     4     drive position  i32, counts of the drive's encoder (x)
    21     1     flags           FrameFlag bits
    22     2     CRC             CRC-16/CCITT (poly 0x1021, init 0xFFFF) of bytes 2..21

The parser keeps no per-frame Python loop: it finds every sync candidate in a chunk,
checks all their CRCs at once (table-driven CRC, one numpy pass per byte column), and
takes the chain of valid frames. Garbage between frames is skipped and counted; a
sequence gap counts lost frames; sequence (u16) and device time (u32) are unwrapped to
int64 so they never wrap in a recording.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from enum import IntFlag

import numpy as np
from numpy.typing import NDArray

log = logging.getLogger(__name__)

__all__ = [
    "FRAME_DTYPE",
    "FRAME_SIZE",
    "FRAME_VERSION",
    "RAW_DTYPE",
    "SYNC",
    "FrameFlag",
    "FrameParser",
    "ParserCounters",
    "crc16_ccitt",
    "encode_frames",
]

SYNC = b"\xa5\x5a"
FRAME_VERSION = 1
FRAME_DTYPE = np.dtype(
    [
        ("sync", "<u2"),
        ("version", "u1"),
        ("seq", "<u2"),
        ("t_us", "<u4"),
        ("force", "<i4"),
        ("weight", "<i4"),
        ("drive", "<i4"),
        ("flags", "u1"),
        ("crc", "<u2"),
    ]
)
FRAME_SIZE = FRAME_DTYPE.itemsize
_CRC_START, _CRC_END = 2, FRAME_SIZE - 2  # CRC covers bytes [2, 22)
_SYNC_U16 = int.from_bytes(SYNC, "little")

#: Parsed frames with unwrapped counters, raw counts (before calibration).
RAW_DTYPE = np.dtype(
    [
        ("seq", "<i8"),
        ("t_device_us", "<i8"),
        ("force", "<i4"),
        ("weight", "<i4"),
        ("drive", "<i4"),
        ("flags", "u1"),
    ]
)


class FrameFlag(IntFlag):
    """Bits of the flags byte."""

    FORCE_OVERLOAD = 0x01
    WEIGHT_FAULT = 0x02
    DRIVE_FAULT = 0x04
    OVERRUN = 0x08  # the front end dropped frames just before this one (buffer full)


def _crc_table() -> NDArray[np.uint16]:
    table = np.zeros(256, dtype=np.uint16)
    for i in range(256):
        crc = i << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else crc << 1
        table[i] = crc & 0xFFFF
    return table


_CRC_TABLE = _crc_table()
_OVERRUN = int(FrameFlag.OVERRUN)  # plain int: IntFlag arithmetic is slow in a hot path
_POSITION_TABLES: dict[int, tuple[NDArray[np.uint16], NDArray[np.intp], np.uint16]] = {}


def _position_tables(length: int) -> tuple[NDArray[np.uint16], NDArray[np.intp], np.uint16]:
    """Per-position CRC contributions of every byte value, and the CRC of zeros.

    The CRC register evolves linearly over GF(2) in (register, data), so the CRC of a
    fixed-length message is the CRC of ``length`` zero bytes (from init 0xFFFF) XOR, for
    each position j, a contribution that depends only on the byte at j. Table row j is
    that contribution for all 256 values: a byte entered with the register at 0, then
    pushed through the ``length − 1 − j`` zero bytes that follow it.
    """
    if length not in _POSITION_TABLES:
        tables = np.zeros((length, 256), dtype=np.uint16)
        contribution = _CRC_TABLE.copy()  # byte b entered with the register at 0
        for j in range(length - 1, -1, -1):
            tables[j] = contribution
            contribution = (contribution << 8) ^ _CRC_TABLE[contribution >> 8]
        zeros = 0xFFFF
        for _ in range(length):
            zeros = ((zeros << 8) & 0xFFFF) ^ int(_CRC_TABLE[zeros >> 8])
        _POSITION_TABLES[length] = (tables, np.arange(length), np.uint16(zeros))
    return _POSITION_TABLES[length]


def crc16_ccitt(data: NDArray[np.uint8]) -> NDArray[np.uint16]:
    """CRC-16/CCITT (poly 0x1021, init 0xFFFF, no reflection) of each row.

    One gather and one XOR-reduction for all rows at once (see ``_position_tables``).

    Parameters
    ----------
    data
        Bytes, shape (frames, length) or (length,).

    Returns
    -------
    CRC per row, shape (frames,) (or a 0-d array for 1-D input).
    """
    rows = np.atleast_2d(np.asarray(data, dtype=np.uint8))
    tables, positions, zeros = _position_tables(rows.shape[1])
    parts = tables[positions, rows]  # (frames, length) contributions
    crc: NDArray[np.uint16] = np.bitwise_xor.reduce(parts, axis=1) ^ zeros
    return crc if np.ndim(data) > 1 else crc.reshape(())


def encode_frames(
    seq: NDArray[np.integer],
    t_us: NDArray[np.integer],
    force: NDArray[np.integer],
    weight: NDArray[np.integer],
    drive: NDArray[np.integer],
    flags: NDArray[np.integer] | int = 0,
    version: int = FRAME_VERSION,
) -> bytes:
    """Frames as the front end sends them (sequence and time are taken modulo their width)."""
    n = len(seq)
    out = np.zeros(n, dtype=FRAME_DTYPE)
    out["sync"] = _SYNC_U16
    out["version"] = version
    out["seq"] = np.asarray(seq, dtype=np.int64) & 0xFFFF
    out["t_us"] = np.asarray(t_us, dtype=np.int64) & 0xFFFFFFFF
    out["force"] = force
    out["weight"] = weight
    out["drive"] = drive
    out["flags"] = flags
    raw = out.view(np.uint8).reshape(n, FRAME_SIZE)
    out["crc"] = crc16_ccitt(raw[:, _CRC_START:_CRC_END])
    return out.tobytes()


@dataclass
class ParserCounters:
    """What the parser has seen since it started (all counts, never reset).

    Attributes
    ----------
    frames
        Valid frames delivered.
    lost
        Frames missing from the sequence (gaps; a corrupted frame is also lost).
    corrupt
        Places where bytes had to be skipped to find the next valid frame (resyncs).
    skipped_bytes
        Bytes discarded while resynchronising.
    overruns
        Frames the front end flagged with OVERRUN (it dropped frames before them).
    """

    frames: int = 0
    lost: int = 0
    corrupt: int = 0
    skipped_bytes: int = 0
    overruns: int = 0


class FrameParser:
    """Turns arbitrary chunks of the byte stream into unwrapped frames.

    Parameters
    ----------
    rate_hz
        The front end's nominal frame rate; used to count gaps longer than the sequence
        counter's period (65536 frames = 32.8 s at 2 kHz) from the device clock.
    """

    def __init__(self, rate_hz: float = 2000.0) -> None:
        self.rate_hz = rate_hz
        self.counters = ParserCounters()
        self._carry = b""
        self._in_garbage = False
        self._lead_in = 0  # bytes skipped before the first valid frame
        self._last_seq: int | None = None  # unwrapped
        self._last_t_us = 0  # unwrapped
        self._long_gap_us = 32768 * 1e6 / rate_hz  # beyond this a u16 wrap may hide

    def feed(self, chunk: bytes) -> NDArray[np.void]:
        """Parse the next chunk; returns the complete valid frames in it (RAW_DTYPE)."""
        data = self._carry + chunk
        buf = np.frombuffer(data, dtype=np.uint8)
        k = len(data) // FRAME_SIZE
        frames = self._aligned(buf, k) if data[:2] == SYNC else None
        if frames is not None:  # the common case: whole frames from the first byte on
            starts = None
            end = k * FRAME_SIZE
        else:
            starts = self._valid_starts(buf)
            end = int(starts[-1]) + FRAME_SIZE if starts.size else 0
            frames = _records(buf, starts)
        keep = _incomplete_tail(data, end)
        if starts is not None or keep > end:
            self._count_skips(starts, end, keep)
        if keep > end:
            self._in_garbage = True
        elif end > 0:
            self._in_garbage = False
        self._carry = data[keep:]
        return self._unwrap(frames)

    @staticmethod
    def _aligned(buf: NDArray[np.uint8], k: int) -> NDArray[np.void] | None:
        """The k frames at offsets 0, 24, 48, … if every one of them is valid."""
        if k == 0:
            return None
        frames = buf[: k * FRAME_SIZE].view(FRAME_DTYPE)
        rows = buf[: k * FRAME_SIZE].reshape(k, FRAME_SIZE)
        ok = (
            (frames["sync"] == _SYNC_U16)
            & (frames["version"] == FRAME_VERSION)
            & (crc16_ccitt(rows[:, _CRC_START:_CRC_END]) == frames["crc"])
        )
        return frames if bool(ok.all()) else None

    def _count_skips(self, starts: NDArray[np.intp] | None, end: int, keep: int) -> None:
        """Count the byte runs skipped before, between and after the accepted frames."""
        if starts is None:  # aligned frames: only the run after them
            run_begin, run_end = np.array([end]), np.array([keep])
        else:
            run_begin = np.concatenate(([0], starts + FRAME_SIZE))
            run_end = np.concatenate((starts, [keep]))
        lengths = run_end - run_begin
        nonempty = lengths > 0
        skipped = int(lengths[nonempty].sum())
        if not skipped:
            return
        runs = int(np.count_nonzero(nonempty))
        if self._last_seq is None and nonempty[0] and run_begin[0] == 0:
            # before the first frame: a reader that opens a streaming port joins it
            # mid-frame; that tail is no corruption, a lead-in of a frame or more is (once)
            before = self._lead_in
            self._lead_in += int(lengths[0])
            runs -= 0 if before < FRAME_SIZE <= self._lead_in else 1
        elif self._in_garbage and nonempty[0] and run_begin[0] == 0:
            runs -= 1  # the garbage run of the previous chunk goes on
        self.counters.skipped_bytes += skipped
        self.counters.corrupt += runs
        log.debug("resync: skipped %d bytes in %d new places", skipped, runs)

    @staticmethod
    def _valid_starts(buf: NDArray[np.uint8]) -> NDArray[np.intp]:
        n = buf.shape[0]
        if n < FRAME_SIZE:
            return np.zeros(0, dtype=np.intp)
        last = n - FRAME_SIZE  # last start with a complete frame
        cand = np.flatnonzero((buf[: last + 1] == SYNC[0]) & (buf[1 : last + 2] == SYNC[1]))
        if cand.size == 0:
            return cand
        frames = _records(buf, cand)
        rows = frames.view(np.uint8).reshape(cand.size, FRAME_SIZE)
        ok = (crc16_ccitt(rows[:, _CRC_START:_CRC_END]) == frames["crc"]) & (
            frames["version"] == FRAME_VERSION
        )
        valid: NDArray[np.intp] = cand[ok]
        if valid.size < 2 or np.all(np.diff(valid) >= FRAME_SIZE):
            return valid
        # A valid-looking frame inside another (a 1-in-65536 CRC accident on a sync pair
        # in the payload): take frames greedily, the first valid one wins.
        chosen: list[int] = []
        for s in valid.tolist():
            if not chosen or s >= chosen[-1] + FRAME_SIZE:
                chosen.append(s)
        return np.asarray(chosen, dtype=np.intp)

    def _unwrap(self, frames: NDArray[np.void]) -> NDArray[np.void]:
        k = frames.shape[0]
        out = np.empty(k, dtype=RAW_DTYPE)
        if k == 0:
            return out
        seq = frames["seq"].astype(np.int64)
        t_us = frames["t_us"].astype(np.int64)
        if self._last_seq is None:
            prev_seq, prev_t = int(seq[0]) - 1, int(t_us[0]) - round(1e6 / self.rate_hz)
        else:
            prev_seq, prev_t = self._last_seq, self._last_t_us
        dseq = np.empty(k, dtype=np.int64)
        dseq[0] = seq[0] - (prev_seq & 0xFFFF)
        np.subtract(seq[1:], seq[:-1], out=dseq[1:])
        dseq &= 0xFFFF
        dt = np.empty(k, dtype=np.int64)
        dt[0] = t_us[0] - (prev_t & 0xFFFFFFFF)
        np.subtract(t_us[1:], t_us[:-1], out=dt[1:])
        dt &= 0xFFFFFFFF
        if dt.max() > self._long_gap_us:
            # The device clock tells how many whole sequence periods a silence hid.
            expected = np.rint(dt * self.rate_hz / 1e6).astype(np.int64)
            periods = np.maximum(np.rint((expected - dseq) / 65536.0), 0).astype(np.int64)
            dseq += periods * 65536
        np.cumsum(dseq, out=out["seq"])
        out["seq"] += prev_seq
        np.cumsum(dt, out=out["t_device_us"])
        out["t_device_us"] += prev_t
        out["force"] = frames["force"]
        out["weight"] = frames["weight"]
        out["drive"] = frames["drive"]
        out["flags"] = frames["flags"]
        last_seq = int(out["seq"][-1])
        duplicates = k - int(np.count_nonzero(dseq))
        lost = last_seq - prev_seq - k + duplicates
        if lost:
            log.debug("sequence gap: %d frames lost", lost)
        self._last_seq, self._last_t_us = last_seq, int(out["t_device_us"][-1])
        self.counters.frames += k
        self.counters.lost += lost
        self.counters.overruns += int(np.count_nonzero(frames["flags"] & _OVERRUN))
        return out


def _records(buf: NDArray[np.uint8], starts: NDArray[np.intp]) -> NDArray[np.void]:
    """The frames starting at ``starts`` as FRAME_DTYPE records (a copy)."""
    rows = buf[starts[:, None] + np.arange(FRAME_SIZE)]
    return np.ascontiguousarray(rows).view(FRAME_DTYPE).reshape(-1)


def _incomplete_tail(data: bytes, end: int) -> int:
    """Where to keep bytes from: the first place after ``end`` a frame may still start."""
    n = len(data)
    for q in range(max(end, n - FRAME_SIZE + 1), n):
        if data[q] == SYNC[0] and (q == n - 1 or data[q + 1] == SYNC[1]):
            return q
    return n
