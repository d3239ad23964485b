"""The feed between the acquisition and the viewer, and the model beside the measurement.

The publisher here stands for the Foxglove server (its own tests are end to end, in
test_live_run.py): one that hangs, one that fails.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from labstand.live.address import parse_address
from labstand.live.feed import LiveFeed
from labstand.live.model import LiveModel, ModelBlock
from recordings.schema import COMMAND_DTYPE, GAUGES_DTYPE
from sim.config import StandConfig
from sim.model import Model

RATE = 2000.0


def _block(seq: NDArray[np.int64], x_mm: NDArray[np.float64]) -> NDArray[np.void]:
    out = np.zeros(len(seq), dtype=GAUGES_DTYPE)
    out["seq"], out["t_ns"], out["x_mm"] = seq, seq * 500_000, x_mm
    return out


class Hanging:
    """A publisher that hangs on the first gauges block until released."""

    def __init__(self) -> None:
        self.release = threading.Event()
        self.samples = 0

    def gauges(self, block: NDArray[np.void]) -> None:
        self.release.wait(30)
        self.samples += len(block)

    def command(self, command: NDArray[np.void]) -> None:
        pass

    def model(self, t_ns: NDArray[np.int64], block: ModelBlock) -> None:
        pass

    def drive(self, row: dict[str, Any]) -> None:
        raise RuntimeError("the viewer broke")

    def event(self, t_ns: int, kind: str, text: str) -> None:
        pass


def test_a_hanging_viewer_drops_and_counts_never_blocks() -> None:
    viewer = Hanging()
    feed = LiveFeed(viewer, None, capacity=4)
    block = _block(np.arange(10), np.zeros(10))
    command = np.zeros(10, dtype=COMMAND_DTYPE)
    start = time.monotonic()
    for _ in range(100):  # the first is taken (and hangs), 4 queue, 95 have no room
        feed.offer_gauges(block, command)
    assert time.monotonic() - start < 5.0  # not a timing test: a blocked put never returns
    viewer.release.set()
    feed.close()
    assert feed.dropped + viewer.samples == 1000
    assert feed.dropped >= 950
    assert feed.summary() == f"viewer dropped {feed.dropped}"


def test_a_failing_viewer_is_logged_counted_and_the_feed_goes_on(
    caplog: pytest.LogCaptureFixture,
) -> None:
    viewer = Hanging()
    viewer.release.set()
    feed = LiveFeed(viewer, None)
    with caplog.at_level(logging.WARNING):
        feed.offer_drive({"t_ns": 0})
        feed.offer_gauges(_block(np.arange(5), np.zeros(5)), np.zeros(5, dtype=COMMAND_DTYPE))
        feed.close()
    assert feed.failures == 1
    assert viewer.samples == 5  # the block after the failure was published
    assert "1 failed" in feed.summary()
    assert "publishing drive failed: the viewer broke" in caplog.text


def test_live_model_block_by_block_is_one_run_and_bridges_lost_samples(
    stand: StandConfig,
) -> None:
    params = stand.stand_params("final", stand.default_mass_kg)
    t = np.arange(4000) / RATE
    x_mm = 20 * np.clip(np.sin(np.pi * t) ** 2, 0, 1) * (t > 0.1)
    whole = Model(params).run(x_mm * 1e-3, RATE)
    live = LiveModel(params, RATE)
    seq = np.arange(4000) + 7
    keep = np.ones(4000, dtype=bool)
    keep[1500:1520] = False  # 20 samples lost
    keep[3001] = False
    got_u, got_f = [], []
    for lo in range(0, 4000, 97):
        part = slice(lo, lo + 97)
        block = _block(seq[part][keep[part]], x_mm[part][keep[part]])
        out = live.advance(block)
        assert len(out.u_mm) == len(block)
        got_u.append(out.u_mm)
        got_f.append(out.force_n)
    u, f = np.concatenate(got_u), np.concatenate(got_f)
    # lost x is bridged linearly; x is smooth, so the model barely notices
    np.testing.assert_allclose(u, whole.u_m[keep] * 1e3, atol=2e-3)
    np.testing.assert_allclose(f, whole.force_n[keep], atol=0.5)
    before = slice(0, 1500)  # before the first gap: the same run exactly
    np.testing.assert_allclose(u[before], whole.u_m[before] * 1e3, rtol=0, atol=1e-9)


def test_residual_is_measured_minus_model(stand: StandConfig) -> None:
    params = stand.stand_params("final", stand.default_mass_kg)
    live = LiveModel(params, RATE)
    block = _block(np.arange(10), np.zeros(10))
    block["u_mm"] = 5.0 + np.arange(10) * 0.1  # rest value 5.0 (the first sample)
    block["force_n"] = 50.0
    out = live.advance(block)
    assert out.u_mm[0] == pytest.approx(5.0)  # the model on the gauge's scale
    np.testing.assert_allclose(out.residual_u_mm, 5.0 + np.arange(10) * 0.1 - out.u_mm)
    np.testing.assert_allclose(out.residual_force_n, 50.0 - out.force_n)
    again = live.advance(block)  # the same samples again: not fed twice
    assert len(again.u_mm) == 0


@pytest.mark.parametrize(
    ("text", "host", "port", "loopback"),
    [
        ("8765", "127.0.0.1", 8765, True),
        ("0", "127.0.0.1", 0, True),
        ("localhost:9000", "localhost", 9000, True),
        ("[::1]:9000", "::1", 9000, True),
        ("0.0.0.0:8765", "0.0.0.0", 8765, False),
    ],
)
def test_address(text: str, host: str, port: int, loopback: bool) -> None:
    address = parse_address(text)
    assert (address.host, address.port, address.loopback) == (host, port, loopback)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("abc", "the port must be a number"),
        (":80", "no host before ':'"),
        ("-1", "out of range"),
    ],
)
def test_bad_address(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        parse_address(text)


def test_a_network_address_warns(caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING):
        parse_address("0.0.0.0:8765")
    assert "open to the network (no authentication)" in caplog.text


def test_the_display_shows_the_viewer_drops() -> None:
    import io

    from labstand.live.view import ViewerDisplay
    from labstand.session.display import PlainDisplay, RunStatus

    viewer = Hanging()
    feed = LiveFeed(viewer, None, capacity=1)
    block = _block(np.arange(10), np.zeros(10))
    for _ in range(5):  # one taken (hangs), one queued, three dropped
        feed.offer_gauges(block, np.zeros(10, dtype=COMMAND_DTYPE))
    out = io.StringIO()
    display = ViewerDisplay(PlainDisplay(out), feed)
    nan = float("nan")
    display.update(RunStatus("running", 1.0, 2.0, nan, nan, nan, 2000.0, 10, 0, 0, "running"))
    viewer.release.set()
    feed.close()
    assert out.getvalue().rstrip().endswith(f"viewer dropped {feed.dropped}")
    assert feed.dropped >= 20


class Stamped(Hanging):
    """A publisher with log times (``epoch_ns`` + recording time), as LiveServer."""

    def __init__(self) -> None:
        super().__init__()
        self.release.set()
        self.epoch_ns = -1
        self.epochs: list[int] = []

    def gauges(self, block: NDArray[np.void]) -> None:
        self.epochs.append(self.epoch_ns)

    def event(self, t_ns: int, kind: str, text: str) -> None:
        self.epochs.append(self.epoch_ns)


def test_log_times_follow_the_least_delayed_gauge_block() -> None:
    walls = iter([5_000, 10_000, 12_500, 12_000, 16_000])  # when each item is offered
    viewer = Stamped()
    feed = LiveFeed(viewer, None, wall_ns=lambda: next(walls))
    command = np.zeros(2, dtype=COMMAND_DTYPE)

    def block(t_last_ns: int) -> NDArray[np.void]:
        out = _block(np.arange(2), np.zeros(2))
        out["t_ns"] = [t_last_ns - 500, t_last_ns]
        return out

    feed.offer_event(0, "note", "before the first sample")  # wall 5 000: for the time being
    feed.offer_gauges(block(1_000), command)  # arrived 9 000 after its t: the gauges rule
    feed.offer_gauges(block(2_000), command)  # 10 500: later than the least delay
    feed.offer_gauges(block(3_000), command)  # 9 000: as early as the first
    feed.offer_gauges(block(8_000), command)  # 8 000: earlier, the epoch moves back
    feed.close()
    assert viewer.epochs == [5_000, 9_000, 9_000, 9_000, 8_000]
