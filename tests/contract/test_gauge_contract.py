"""What every ``GaugeSource`` backend must do, run against each (conftest.gauge_rig).

The simulated front end streams real frames into a raw pty that the driver opens like
``/dev/ttyUSB0``; marked ``hardware``, the same tests read the stand's front end.
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest
from numpy.typing import NDArray

from drivers.errors import ClosedError
from drivers.interfaces import SAMPLE_DTYPE, GaugeSource, GaugeStats
from recordings.schema import concat_blocks
from tests.contract.conftest import GaugeRig

#: Enough samples to see the rate and the sequence: 0.5 s at 2 kHz.
SAMPLES = 1000


@pytest.fixture
def gauges(gauge_rig: GaugeRig) -> Iterator[GaugeSource]:
    """A fresh gauge source, closed afterwards (the stream is left running)."""
    if gauge_rig.silence is not None:
        gauge_rig.silence(False)
    source = gauge_rig.open()
    try:
        yield source
    finally:
        source.close()
        if gauge_rig.silence is not None:
            gauge_rig.silence(False)


def _collect(source: GaugeSource, n: int, timeout_s: float = 10.0) -> NDArray[np.void]:
    blocks, count = [], 0
    deadline = time.monotonic() + timeout_s
    while count < n:
        assert time.monotonic() < deadline, f"only {count} of {n} samples in {timeout_s:g} s"
        block = source.read_block(0.1)
        if block is not None and len(block):
            blocks.append(block)
            count += len(block)
    return concat_blocks(blocks)


def test_samples_arrive_at_the_rate_with_consecutive_sequence_numbers(
    gauges: GaugeSource, gauge_rig: GaugeRig
) -> None:
    samples = _collect(gauges, SAMPLES)
    assert samples.dtype == SAMPLE_DTYPE
    assert np.all(np.diff(samples["seq"]) == 1)
    # the device clock ticks once per sample at the front end's rate
    period_us = 1e6 / gauge_rig.rate_hz
    assert np.all(np.diff(samples["t_device_us"]) == pytest.approx(period_us, abs=1.0))
    assert gauges.rate_hz == gauge_rig.rate_hz == 2000.0
    for channel in ("force_n", "u_mm", "x_mm"):
        assert np.all(np.isfinite(samples[channel])), channel
    host = samples["t_host_ns"]
    assert np.all(np.diff(host) >= 0)  # arrival stamps never go back
    stats = gauges.stats()
    assert isinstance(stats, GaugeStats)
    assert stats.frames >= len(samples) and stats.lost == 0


def test_a_closed_source_refuses_work(gauges: GaugeSource) -> None:
    assert len(_collect(gauges, 1)) >= 1
    gauges.close()
    gauges.close()  # idempotent
    assert gauges.closed
    with pytest.raises(ClosedError, match="closed"):
        gauges.read_block(0.0)
    with pytest.raises(ClosedError, match="closed"):
        gauges.__enter__()
    assert isinstance(gauges.stats(), GaugeStats)  # the counters stay readable


def test_a_negative_time_out_is_refused(gauges: GaugeSource) -> None:
    with pytest.raises(ValueError, match="timeout must be ≥ 0 s"):
        gauges.read_block(-0.1)


def test_a_silent_source_returns_nothing_within_its_time_out(
    gauges: GaugeSource, gauge_rig: GaugeRig
) -> None:
    if gauge_rig.silence is None:
        pytest.skip("the real front end cannot be silenced from here")
    _collect(gauges, 100)
    gauge_rig.silence(True)
    deadline = time.monotonic() + 5.0
    while gauges.read_block(0.0) is not None:  # what was sent before the silence
        assert time.monotonic() < deadline, "the stream did not fall silent"
    empty = 0
    for _ in range(5):
        t0 = time.monotonic()
        block = gauges.read_block(0.1)
        elapsed = time.monotonic() - t0
        if block is None:
            empty += 1
            assert elapsed < 0.1 + 0.5, f"{elapsed:.2f} s"
    assert empty >= 4  # at most one block still in flight
    seq_before = gauges.stats().frames
    gauge_rig.silence(False)
    resumed = _collect(gauges, 100)
    assert gauges.stats().frames > seq_before and len(resumed) >= 100
