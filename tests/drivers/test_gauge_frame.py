"""The gauge frame and its vectorised parser: layout, CRC, resync, counters, unwrapping."""

from __future__ import annotations

import binascii
import struct

import numpy as np
import pytest

from drivers.gauge_frame import (
    FRAME_SIZE,
    SYNC,
    FrameFlag,
    FrameParser,
    crc16_ccitt,
    encode_frames,
)


def frames(n: int, seq0: int = 0, t0: int = 0, flags: int = 0) -> bytes:
    idx = np.arange(n, dtype=np.int64)
    return encode_frames(seq0 + idx, t0 + 500 * idx, 1000 + idx, -7 * idx, 3 * idx, flags=flags)


def test_crc_is_ccitt_false() -> None:
    data = np.frombuffer(b"123456789", dtype=np.uint8)
    assert int(crc16_ccitt(data)) == 0x29B1  # the catalogued check value
    rng = np.random.default_rng(1)
    rows = rng.integers(0, 256, (50, 20), dtype=np.uint8)
    expected = [binascii.crc_hqx(r.tobytes(), 0xFFFF) for r in rows]
    assert crc16_ccitt(rows).tolist() == expected


def test_layout_matches_the_documented_frame() -> None:
    raw = encode_frames(
        np.array([0xBEEF]),
        np.array([0xDEADBEEF]),
        np.array([-5]),
        np.array([123456]),
        np.array([-654321]),
        flags=FrameFlag.OVERRUN,
    )
    assert len(raw) == FRAME_SIZE == 24
    sync, ver, seq, t_us, force, weight, drive, flags, crc = struct.unpack("<2sBHIiiiBH", raw)
    assert (sync, ver, seq, t_us) == (SYNC, 1, 0xBEEF, 0xDEADBEEF)
    assert (force, weight, drive, flags) == (-5, 123456, -654321, 0x08)
    assert crc == binascii.crc_hqx(raw[2:22], 0xFFFF)


def test_any_chunking_gives_the_same_frames() -> None:
    data = frames(40)
    whole = FrameParser().feed(data)
    for size in (1, 5, 23, 24, 25, 100):
        p = FrameParser()
        parts = [p.feed(data[i : i + size]) for i in range(0, len(data), size)]
        got = np.concatenate(parts)
        assert np.array_equal(got, whole)
        assert (p.counters.frames, p.counters.lost, p.counters.corrupt) == (40, 0, 0)
    assert whole["seq"].tolist() == list(range(40))
    assert whole["drive"].tolist() == [3 * i for i in range(40)]


def test_garbage_between_frames_is_skipped_and_counted() -> None:
    good = frames(30)
    garbage = [b"\x00\x01\x02", SYNC + b"\x99" * 30, b"\xa5", b"\xa5\x5a\xa5\x5a\x00" * 3]
    stream = b""
    for i in range(30):
        stream += good[i * 24 : (i + 1) * 24]
        if i % 7 == 3:
            stream += garbage[(i // 7) % len(garbage)]
    p = FrameParser()
    out = np.concatenate([p.feed(stream[i : i + 37]) for i in range(0, len(stream), 37)])
    assert out["seq"].tolist() == list(range(30))
    inserted = [garbage[(i // 7) % len(garbage)] for i in range(30) if i % 7 == 3]
    assert p.counters.corrupt == len(inserted)
    assert p.counters.skipped_bytes == sum(map(len, inserted))
    assert p.counters.lost == 0


def test_garbage_before_the_first_frame() -> None:
    p = FrameParser()
    out = p.feed(b"\xff" * 50 + frames(3))
    assert out["seq"].tolist() == [0, 1, 2]
    assert (p.counters.corrupt, p.counters.skipped_bytes) == (1, 50)


@pytest.mark.parametrize("chunk", [7, 24, 1000])
def test_joining_a_stream_mid_frame_is_not_corruption(chunk: int) -> None:
    # a reader opening a port that already streams starts inside a frame
    stream = frames(20)[13:]
    p = FrameParser()
    out = np.concatenate([p.feed(stream[i : i + chunk]) for i in range(0, len(stream), chunk)])
    assert out["seq"].tolist() == list(range(1, 20))
    assert (p.counters.corrupt, p.counters.skipped_bytes, p.counters.lost) == (0, 11, 0)
    p.feed(b"\x00\x01\x02" + frames(1, seq0=20, t0=10_000))  # later garbage still counts
    assert (p.counters.corrupt, p.counters.skipped_bytes) == (1, 14)


@pytest.mark.parametrize("chunk", [7, 1000])
def test_a_lead_in_of_a_frame_or_more_is_corruption_once(chunk: int) -> None:
    stream = b"\xff" * 30 + frames(5)
    p = FrameParser()
    out = np.concatenate([p.feed(stream[i : i + chunk]) for i in range(0, len(stream), chunk)])
    assert out["seq"].tolist() == list(range(5))
    assert (p.counters.corrupt, p.counters.skipped_bytes) == (1, 30)


def test_a_corrupted_frame_is_lost_and_counted() -> None:
    data = bytearray(frames(10))
    data[5 * 24 + 10] ^= 0x40  # one bit flipped in frame 5's force
    p = FrameParser()
    out = p.feed(bytes(data))
    assert out["seq"].tolist() == [0, 1, 2, 3, 4, 6, 7, 8, 9]
    assert (p.counters.lost, p.counters.corrupt, p.counters.skipped_bytes) == (1, 1, 24)


def test_sequence_and_clock_unwrap() -> None:
    p = FrameParser()
    seq0, t0 = 65530, 2**32 - 1500
    out = np.concatenate([p.feed(frames(20, seq0, t0)[i : i + 48]) for i in range(0, 480, 48)])
    assert out["seq"].tolist() == list(range(seq0, seq0 + 20))
    assert np.all(np.diff(out["t_device_us"]) == 500)
    assert out["t_device_us"][0] == t0 and out["t_device_us"][-1] == t0 + 19 * 500
    assert p.counters.lost == 0


def test_gaps_are_counted_across_the_wrap() -> None:
    all_frames = frames(40, 65520, 0)
    keep = [i for i in range(40) if i not in {3, 4, 15, 16, 17, 39}]
    data = b"".join(all_frames[i * 24 : (i + 1) * 24] for i in keep)
    p = FrameParser()
    out = p.feed(data)
    assert p.counters.lost == 5  # the trailing missing frame is not known yet
    assert out["seq"].tolist() == [65520 + i for i in keep]


def test_a_gap_longer_than_the_sequence_period_is_counted_from_the_clock() -> None:
    p = FrameParser(rate_hz=2000.0)
    p.feed(frames(5, 100, 0))
    lost = 70_000  # 35 s of silence: the u16 sequence wrapped once unseen
    out = p.feed(frames(5, 105 + lost, (5 + lost) * 500))
    assert p.counters.lost == lost
    assert out["seq"][0] == 105 + lost


def test_overrun_flags_are_counted() -> None:
    p = FrameParser()
    p.feed(frames(3, flags=FrameFlag.OVERRUN) + frames(2, 3, 1500))
    assert p.counters.overruns == 3


def test_wrong_version_is_not_a_frame() -> None:
    idx = np.arange(3)
    data = encode_frames(idx, idx * 500, idx, idx, idx, version=2)
    p = FrameParser()
    assert p.feed(data).size == 0
    assert p.counters.skipped_bytes > 0


@pytest.mark.parametrize("cut", [1, 2, 12, 23])
def test_a_trailing_partial_frame_waits_for_its_rest(cut: int) -> None:
    data = frames(2)
    p = FrameParser()
    assert p.feed(data[: 24 + cut]).size == 1
    assert p.feed(data[24 + cut :]).size == 1
    assert (p.counters.corrupt, p.counters.lost) == (0, 0)
