"""Gauge-frame parser throughput in frames/s, against the 2 kHz the stand needs.

Compares ``drivers.gauge_frame.FrameParser`` (vectorised) with a naive per-frame loop
(``bytes.find`` for the sync, ``binascii.crc_hqx`` for the CRC, ``struct.unpack`` per
frame) on the same byte stream, fed in chunks the size a reader gets per read: 10 ms of
frames (a pty read), 16 ms (a USB-serial adapter's latency timer) and 1 s. A stream with
garbage (one corrupted frame in 100) checks the resync path too.

``--live SECONDS`` also starts ``labstand stand-sim`` (a separate process) and reads its
2 kHz stream over the pty with ``SerialGaugeStream`` while polling the drive at 20 Hz,
for each Modbus link (TCP, RTU on a pty pair): frames, lost frames, this process's CPU
time as a share of one core, and the poll round-trip times. Run::

    .venv/bin/python benchmarks/bench_gauge_parser.py [--frames 200000] [--live 10]
"""

from __future__ import annotations

import argparse
import binascii
import struct
import time

import numpy as np

from drivers.gauge_frame import FRAME_SIZE, SYNC, FrameParser, encode_frames

NEED_HZ = 2000.0
_FMT = struct.Struct("<2sBHIiiiBH")


class NaiveParser:
    """The reference: one frame at a time in Python."""

    def __init__(self) -> None:
        self.buf = b""
        self.frames = 0

    def feed(self, chunk: bytes) -> list[tuple[int, ...]]:
        buf = self.buf + chunk
        out = []
        i = 0
        while True:
            i = buf.find(SYNC, i)
            if i < 0 or i + FRAME_SIZE > len(buf):
                break
            frame = buf[i : i + FRAME_SIZE]
            fields = _FMT.unpack(frame)
            if binascii.crc_hqx(frame[2:22], 0xFFFF) == fields[-1]:
                out.append(fields[2:8])
                i += FRAME_SIZE
            else:
                i += 1
        self.buf = buf[i if i >= 0 else len(buf) :]
        self.frames += len(out)
        return out


def stream(n: int, corrupt_every: int = 0) -> bytes:
    idx = np.arange(n, dtype=np.int64)
    rng = np.random.default_rng(0)
    force = rng.integers(0, 200_000, n)
    data = bytearray(encode_frames(idx, 500 * idx, force, -idx, 3 * idx))
    if corrupt_every:
        for k in range(corrupt_every // 2, n, corrupt_every):
            data[k * FRAME_SIZE + 12] ^= 0xFF
    return bytes(data)


def bench(parser: FrameParser | NaiveParser, data: bytes, chunk: int) -> tuple[float, int]:
    t0 = time.perf_counter()
    for i in range(0, len(data), chunk):
        parser.feed(data[i : i + chunk])
    dt = time.perf_counter() - t0
    frames = parser.counters.frames if isinstance(parser, FrameParser) else parser.frames
    return dt, frames


def live(seconds: float, modbus: str) -> None:
    from drivers.gauge_stream import SerialGaugeStream
    from drivers.unidrive import open_unidrive
    from sim.config import default_config
    from sim.hardware.process import StandProcess

    config = default_config()
    with StandProcess(["--modbus", modbus]) as sim:
        ep = sim.endpoints
        with (
            SerialGaugeStream(ep["gauges"], config.gauges) as gauges,
            open_unidrive(ep["modbus"], config.drive) as drive,
        ):
            frames, rtt = 0, []
            cpu0, t0 = time.process_time(), time.monotonic()
            next_poll = t0
            while time.monotonic() - t0 < seconds:
                if time.monotonic() >= next_poll:
                    t = time.perf_counter()
                    drive.poll()
                    rtt.append(time.perf_counter() - t)
                    next_poll += 0.05
                block = gauges.read_block(0.01)
                frames += 0 if block is None else len(block)
            cpu = (time.process_time() - cpu0) / (time.monotonic() - t0)
            stats = gauges.stats()
    ms = np.percentile(np.array(rtt) * 1e3, [50, 99])
    link = modbus.split(":", maxsplit=1)[0]
    print(
        f"live {link:>4}: {frames} frames in {seconds:g} s ({frames / seconds:.0f}/s), "
        f"lost {stats.lost}, corrupt {stats.corrupt}; reader + 20 Hz polling: "
        f"{cpu:.1%} of one core; poll round trip p50 {ms[0]:.2f} ms, p99 {ms[1]:.2f} ms"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=200_000)
    ap.add_argument("--live", type=float, default=0.0, metavar="SECONDS")
    args = ap.parse_args()
    print(f"need: {NEED_HZ:.0f} frames/s; {args.frames} frames per case")
    print(f"{'stream':<16}{'chunk':>12}{'vectorised':>16}{'naive':>14}{'ratio':>8}{'× need':>10}")
    for label, corrupt in (("clean", 0), ("1 % corrupted", 100)):
        data = stream(args.frames, corrupt)
        for chunk_frames, chunk_label in ((20, "10 ms"), (32, "16 ms"), (2000, "1 s")):
            chunk = chunk_frames * FRAME_SIZE
            dt_v, n_v = bench(FrameParser(), data, chunk)
            dt_n, n_n = bench(NaiveParser(), data, chunk)
            if n_v != n_n:
                raise SystemExit(f"parsers disagree: {n_v} vs {n_n} frames")
            fv, fn = n_v / dt_v, n_n / dt_n
            print(
                f"{label:<16}{chunk_label:>12}{fv:>14,.0f}/s{fn:>12,.0f}/s"
                f"{fv / fn:>7.1f}×{fv / NEED_HZ:>9,.0f}×"
            )
    if args.live > 0:
        for modbus in ("tcp://127.0.0.1:0", "rtu"):
            live(args.live, modbus)


if __name__ == "__main__":
    main()
