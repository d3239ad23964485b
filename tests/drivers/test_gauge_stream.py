"""The serial gauge stream: reader thread, calibration, queue, failures, closing."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest
import serial

from drivers.calibration import GaugeCalibration
from drivers.gauge_frame import encode_frames
from drivers.gauge_stream import (
    GaugeClosedError,
    GaugeConnectionError,
    GaugeError,
    SerialGaugeStream,
)
from drivers.interfaces import SAMPLE_DTYPE, ClosedError
from sim.hardware.pty import open_raw_pty

CAL = GaugeCalibration(
    force_n_per_count=0.002,
    force_offset_n=1.0,
    position_mm_per_count=0.001,
    position_offset_mm=-2.0,
    drive_mm_per_count=0.0005,
    drive_offset_mm=0.5,
)


def frames(n: int, seq0: int = 0) -> bytes:
    idx = np.arange(seq0, seq0 + n, dtype=np.int64)
    return encode_frames(idx, 500 * idx, 100 * idx, -idx, 2 * idx)


def collect(stream: SerialGaugeStream, n: int, timeout_s: float = 5.0) -> np.ndarray:
    got: list[np.ndarray] = []
    deadline = time.monotonic() + timeout_s
    while sum(map(len, got)) < n and time.monotonic() < deadline:
        block = stream.read_block(0.05)
        if block is not None:
            got.append(block)
    return np.concatenate(got) if got else np.empty(0, SAMPLE_DTYPE)


def test_loopback_blocks_are_calibrated() -> None:
    port = serial.serial_for_url("loop://", timeout=0.02)
    with SerialGaugeStream(port, CAL, flush_on_open=False) as stream:
        port.write(frames(100)[:1000])
        port.write(frames(100)[1000:])
        out = collect(stream, 100)
        assert out.dtype == SAMPLE_DTYPE
        assert out["seq"].tolist() == list(range(100))
        i = np.arange(100)
        np.testing.assert_allclose(out["force_n"], 1.0 + 0.002 * 100 * i)
        np.testing.assert_allclose(out["u_mm"], -2.0 - 0.001 * i)
        np.testing.assert_allclose(out["x_mm"], 0.5 + 0.0005 * 2 * i)
        assert np.all(np.diff(out["t_device_us"]) == 500)
        assert np.all(out["t_host_ns"] > 0)
        s = stream.stats()
        assert (s.frames, s.lost, s.corrupt, s.bytes_read) == (100, 0, 0, 2400)
    assert stream.closed
    with pytest.raises(GaugeClosedError):
        stream.read_block(0.0)
    assert issubclass(GaugeClosedError, ClosedError)


def test_full_queue_drops_blocks_and_counts_them() -> None:
    port = serial.serial_for_url("loop://", timeout=0.02)
    with SerialGaugeStream(port, CAL, queue_blocks=1, flush_on_open=False) as stream:
        for k in range(5):
            port.write(frames(10, 10 * k))
            deadline = time.monotonic() + 2
            while stream.stats().frames < 10 * (k + 1) and time.monotonic() < deadline:
                time.sleep(0.005)
        s = stream.stats()
        assert s.frames == 50
        assert s.dropped_blocks == 4  # the consumer never read: one block kept
        assert stream.read_block(0.0) is not None
        assert stream.read_block(0.0) is None


def test_real_pty_and_a_vanishing_port() -> None:
    pty = open_raw_pty()
    try:
        stream = SerialGaugeStream(pty.path, CAL)
        try:
            os.write(pty.master_fd, frames(50))
            assert collect(stream, 50)["seq"].tolist() == list(range(50))
            pty.close()  # the front end is unplugged
            deadline = time.monotonic() + 3
            with pytest.raises(GaugeConnectionError, match="reading failed"):
                while time.monotonic() < deadline:
                    stream.read_block(0.05)
        finally:
            stream.close()
    finally:
        pty.close()


def test_bad_path_is_a_connection_error() -> None:
    with pytest.raises(GaugeConnectionError, match="cannot open /nonexistent/tty") as err:
        SerialGaugeStream("/nonexistent/tty", CAL)
    assert isinstance(err.value, ConnectionError) and isinstance(err.value, GaugeError)


def test_negative_timeout_is_refused() -> None:
    port = serial.serial_for_url("loop://", timeout=0.02)
    with SerialGaugeStream(port, CAL) as stream, pytest.raises(ValueError, match="timeout"):
        stream.read_block(-1)
