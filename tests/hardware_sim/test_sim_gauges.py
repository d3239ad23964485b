"""The simulated gauge front end over a real pty, read by the gauge stream driver."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest
import serial

from drivers.gauge_frame import SYNC, FrameFlag, FrameParser
from drivers.gauge_stream import SerialGaugeStream
from drivers.interfaces import SAMPLE_DTYPE
from drivers.signals import Shape, SignalSpec
from drivers.unidrive import open_unidrive
from drivers.unidrive_profile import ProfileState
from sim.config import StandConfig
from sim.hardware.gauges import FrontEndSettings
from sim.model import Model
from tests.hardware_sim.conftest import run_stand


def read_for(stream: SerialGaugeStream, wall_s: float) -> np.ndarray:
    blocks = []
    deadline = time.monotonic() + wall_s
    while time.monotonic() < deadline:
        if (b := stream.read_block(0.02)) is not None:
            blocks.append(b)
    return np.concatenate(blocks) if blocks else np.empty(0, SAMPLE_DTYPE)


def check_contiguous(samples: np.ndarray) -> None:
    assert np.all(np.diff(samples["seq"]) == 1)
    assert np.all(np.diff(samples["t_device_us"]) == 500)


def test_zero_lost_frames_at_2khz_faster_than_real_time(config: StandConfig) -> None:
    speed = 4.0  # 8000 frames per wall second through the pty
    thread = run_stand(config, speed=speed)
    ep = thread.start()
    try:
        with SerialGaugeStream(ep.gauges, config.gauges) as stream:
            samples = read_for(stream, 1.5)
            stats = stream.stats()
    finally:
        thread.stop()
    assert len(samples) >= 0.8 * 1.5 * speed * 2000  # ≈ 12 000 frames, 6 s of stand time
    check_contiguous(samples)
    assert (stats.lost, stats.corrupt, stats.overruns, stats.dropped_blocks) == (0, 0, 0, 0)
    assert thread.stand.writer is None  # closed with the stand


def test_sequence_and_clock_wrap_on_the_wire(config: StandConfig) -> None:
    fe = FrontEndSettings(seq_start=65536 - 1000, clock_start_us=2**32 - 300_000)
    thread = run_stand(config, speed=4.0, frontend=fe)
    ep = thread.start()
    try:
        with SerialGaugeStream(ep.gauges, config.gauges) as stream:
            samples = read_for(stream, 0.8)
            stats = stream.stats()
    finally:
        thread.stop()
    check_contiguous(samples)
    assert samples["seq"][-1] > 65536 + 1000  # crossed the u16 wrap, unwrapped
    assert samples["t_device_us"][-1] > 2**32  # crossed the u32 µs wrap, unwrapped
    assert stats.lost == 0


def test_garbage_on_the_line_is_resynchronised(config: StandConfig) -> None:
    thread = run_stand(config, speed=2.0)
    ep = thread.start()
    garbage = [b"\x00" * 7, SYNC + b"\x01" * 40, b"\xa5", bytes(range(256))]
    try:
        with SerialGaugeStream(ep.gauges, config.gauges) as stream:
            fd = thread.stand._gauge_pty.master_fd  # type: ignore[union-attr]
            parts = [read_for(stream, 0.1)]
            for g in garbage:  # written between frames, from the stand's own loop
                thread.call(lambda g=g: os.write(fd, g))
                parts.append(read_for(stream, 0.1))
            parts.append(read_for(stream, 0.2))
            stats = stream.stats()
    finally:
        thread.stop()
    samples = np.concatenate(parts)
    check_contiguous(samples)  # garbage between frames costs no frame
    assert stats.corrupt == len(garbage)
    assert stats.skipped_bytes == sum(map(len, garbage))
    assert stats.lost == 0


def read_raw(port: serial.Serial, parser: FrameParser, wall_s: float) -> np.ndarray:
    parts = []
    deadline = time.monotonic() + wall_s
    while time.monotonic() < deadline:
        parts.append(parser.feed(port.read(max(1, port.in_waiting))))
    return np.concatenate(parts)


def test_nobody_reading_overruns_like_a_uart(config: StandConfig) -> None:
    thread = run_stand(config, speed=4.0)
    ep = thread.start()
    writer = thread.stand.writer
    assert writer is not None
    parser = FrameParser()
    try:
        with serial.Serial(ep.gauges, timeout=0.01) as port:
            before = read_raw(port, parser, 0.2)
            assert thread.call(lambda: writer.dropped) == 0
            deadline = time.monotonic() + 5.0  # stop reading until the pty (≈ 0.5 s) overflows
            while thread.call(lambda: writer.dropped) < 1000:
                assert time.monotonic() < deadline
                time.sleep(0.02)
            after = read_raw(port, parser, 0.5)
            dropped = thread.call(lambda: writer.dropped)
    finally:
        thread.stop()
    assert dropped > 1000
    assert parser.counters.lost == dropped  # every frame the front end dropped is seen lost
    assert parser.counters.corrupt == 0  # only whole frames are dropped
    samples = np.concatenate([before, after])
    gaps = np.flatnonzero(np.diff(samples["seq"]) != 1)
    assert len(gaps) >= 1
    assert samples["flags"][gaps[0] + 1] & FrameFlag.OVERRUN  # the frame after the gap says so
    assert parser.counters.overruns == len(gaps)


def test_gauges_follow_the_drive_through_the_model(config: StandConfig) -> None:
    thread = run_stand(config, speed=2.0)
    ep = thread.start()
    spec = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.03, 1.0, 2, dwell_start_s=0.2, dwell_end_s=0.5)
    try:
        with (
            SerialGaugeStream(ep.gauges, config.gauges) as stream,
            open_unidrive(ep.modbus, config.drive) as drive,
        ):
            drive.check_limits()
            drive.enable()
            drive.load_profile(spec)
            drive.start()
            blocks = []
            while (state := drive.poll()).profile_state is not ProfileState.DONE:
                assert not state.tripped
                if (b := stream.read_block(0.01)) is not None:
                    blocks.append(b)
            blocks.append(read_for(stream, 0.1))
    finally:
        thread.stop()
    s = np.concatenate(blocks)
    check_contiguous(s)
    assert s["x_mm"].max() == pytest.approx(30.0, abs=0.1)
    # u and F are the stand model driven by the x the drive really ran (it started at rest)
    params = config.stand_params("final")
    x_m = s["x_mm"] / 1e3
    ref = Model(params).run(x_m, 2000.0)
    assert np.sqrt(np.mean((s["u_mm"] - ref.u_m * 1e3) ** 2)) < 0.005  # noise 0.5 µm
    assert np.sqrt(np.mean((s["force_n"] - ref.force_n) ** 2)) < 0.1  # noise 0.02 N
    assert s["force_n"].max() > params.preload_tension_n + 10
