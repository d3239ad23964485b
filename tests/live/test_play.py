"""``labstand play``: a recording to Foxglove at real time, on an injected clock in tests.

The player's pacing runs on a simulated clock (no waiting, no timing in the test); the
command end to end serves a real file to the independent Node client.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from labstand.cli import main
from labstand.live.model import ModelBlock
from labstand.live.player import BLOCK_S, Player
from recordings import RecordingMetadata, open_recording, open_writer
from tests.live.conftest import NodeClient, read_url
from tests.ptys import sigint_not_ignored
from tests.run.conftest import Outcome, labstand_process


class SimClock:
    """Simulated time: ``sleep`` advances it at once."""

    def __init__(self) -> None:
        self.t = 100.0

    def now(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        assert seconds > 0
        self.t += seconds


class Collector:
    """What a publisher would have sent, with the clock's time of each gauges block."""

    def __init__(self, clock: SimClock) -> None:
        self.clock = clock
        self.gauge_times: list[tuple[float, int, int]] = []  # (clock, first t_ns, n)
        self.seq: list[int] = []
        self.model_n = 0
        self.command_n = 0
        self.drive: list[dict[str, Any]] = []
        self.events: list[tuple[int, str, str]] = []

    def gauges(self, block: NDArray[np.void]) -> None:
        self.gauge_times.append((self.clock.t, int(block["t_ns"][-1]), len(block)))
        self.seq += block["seq"].tolist()

    def command(self, command: NDArray[np.void]) -> None:
        self.command_n += len(command)

    def model(self, t_ns: NDArray[np.int64], block: ModelBlock) -> None:
        assert len(t_ns) == len(block.u_mm)
        self.model_n += len(t_ns)

    def drive(self, row: dict[str, Any]) -> None:
        self.drive.append(row)

    def event(self, t_ns: int, kind: str, text: str) -> None:
        self.events.append((t_ns, kind, text))


@pytest.fixture
def s11(tmp_path: Path) -> Path:
    """``labstand simulate --situation 11`` as MCAP: 4 s, 8001 samples, 2 events."""
    out = tmp_path / "s11.mcap"
    assert main(["simulate", "--situation", "11", "-o", str(out)]) == 0
    return out


@pytest.mark.parametrize("speed", [1.0, 4.0])
def test_player_paces_every_block_by_its_time(s11: Path, speed: float) -> None:
    rec = open_recording(s11)
    params = rec_params(rec)
    clock = SimClock()
    seen = Collector(clock)
    stats = Player(rec, seen, params, clock, speed=speed).play()
    assert stats.samples == len(rec.gauges) == seen.model_n
    assert seen.seq == rec.gauges["seq"].tolist()
    assert seen.command_n == len(rec.command)
    assert [e[1] for e in seen.events] == rec.events_array["kind"].tolist()
    t0 = int(rec.gauges["t_ns"][0])
    for clock_s, t_end_ns, _ in seen.gauge_times:  # published when the clock reached it
        assert clock_s == pytest.approx(100.0 + (t_end_ns - t0) / 1e9 / speed, abs=1e-9)
    assert seen.gauge_times[0][2] == round(BLOCK_S * 2000)


def test_player_starts_late_and_stops_when_asked(s11: Path) -> None:
    rec = open_recording(s11)
    clock = SimClock()
    seen = Collector(clock)
    player = Player(rec, seen, None, clock, start_s=3.0)
    player.play()
    assert seen.seq[0] == int(rec.gauges["seq"][np.searchsorted(rec.gauges["t_ns"], 3e9)])
    assert seen.seq[-1] == int(rec.gauges["seq"][-1])
    assert seen.model_n == 0  # no parameters: no model
    calls = iter(range(1000))
    stopped = Collector(clock)
    Player(rec, stopped, None, clock).play(stop=lambda: next(calls) >= 3)
    assert len(stopped.gauge_times) == 3


def rec_params(rec: Any) -> Any:
    from labstand.recording_stand import params_for

    return params_for(rec, None, "final", None)[0]


def test_play_serves_the_file_to_an_independent_client(
    s11: Path, node_client: type[NodeClient]
) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "labstand", "play", str(s11), "--speed", "4", "--foxglove", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        url = read_url(proc.stdout, [])
        report = node_client(url).finish()  # play waits for the client's subscription
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    rec = open_recording(s11)
    assert f"pass 1: {len(rec.gauges)} samples" in out
    topics = report["topics"]
    assert report["server"] == "labstand play s11.mcap"
    # the file's samples, count and times
    assert topics["/gauges"]["seq"] == rec.gauges["seq"].tolist()
    assert topics["/gauges"]["tNs"] == rec.gauges["t_ns"].tolist()
    log_times = np.array([int(t) for t in topics["/gauges"]["logTimes"]], dtype=np.int64)
    assert np.all(log_times - rec.gauges["t_ns"] == log_times[0] - rec.gauges["t_ns"][0])
    assert np.all(np.diff(log_times) == np.diff(rec.gauges["t_ns"]))  # one fixed epoch
    # the model's replay and the residual beside them; the file is the model's own
    # simulation, so the residual is tiny
    assert topics["/model"]["tNs"] == rec.gauges["t_ns"].tolist()
    assert topics["/model/residual"]["count"] == len(rec.gauges)
    assert abs(topics["/model/residual"]["last"]["force_n"]) < 1e-6
    assert topics["/events"]["count"] == len(rec.events_array)


def test_a_recording_without_gauges_is_bad_input(
    tmp_path: Path, labstand: Callable[..., Outcome], meta: RecordingMetadata
) -> None:
    path = tmp_path / "no-gauges.mcap"
    with open_writer(path, meta) as writer:
        writer.write_event(0, "note", "nothing measured")
    result = labstand("play", path, "--foxglove", "0", "--no-wait")
    assert result.code == 2
    assert result.err == f"labstand: error: {path}: the gauges stream holds no samples\n"


def test_start_beyond_the_end_is_bad_input(s11: Path, labstand: Callable[..., Outcome]) -> None:
    result = labstand("play", s11, "--start", "9", "--foxglove", "0")
    assert result.code == 2
    assert result.err == (f"labstand: error: --start 9 s is outside {s11} (0 … 4.000 s)\n")


def test_busy_port_is_bad_input(s11: Path) -> None:
    import socket

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        result = labstand_process("play", s11, "--foxglove", str(port))
    assert result.code == 2
    assert result.err.startswith(f"labstand: error: --foxglove 127.0.0.1:{port}:")
    assert len(result.err.splitlines()) == 1


def test_loop_plays_again_later_on_the_time_axis(s11: Path, node_client: type[NodeClient]) -> None:
    import signal

    with sigint_not_ignored():
        proc = subprocess.Popen(
            [sys.executable, "-m", "labstand", "play", str(s11), "--speed", "20", "--loop",
             "--start", "2", "--foxglove", "0"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )  # fmt: skip
    try:
        assert proc.stdout is not None
        client = node_client(read_url(proc.stdout, []))
        passes = 0
        for line in proc.stdout:  # until the third pass has ended
            passes += line.startswith("  pass ")
            if passes == 3:
                break
        proc.send_signal(signal.SIGINT)  # Ctrl-C ends a loop
        report = client.finish()
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130
    assert err.strip().splitlines()[-1] == "labstand: interrupted"
    rec = open_recording(s11)
    one_pass = rec.gauges["seq"][rec.gauges["t_ns"] >= 2e9].tolist()
    seq = report["topics"]["/gauges"]["seq"]
    assert seq[: 3 * len(one_pass)] == one_pass * 3  # from --start to the end, again
    log_times = np.array([int(t) for t in report["topics"]["/gauges"]["logTimes"]])
    assert np.all(np.diff(log_times) > 0)  # each pass later than the one before
