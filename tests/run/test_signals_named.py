"""SIGTERM is named as it came: exit 143, "terminated", in ``run`` and ``play`` alike.

A run stopped by SIGTERM stops in order (as a first Ctrl-C does) and says SIGTERM, not
Ctrl-C; ``play`` ends with one line, not a death by the signal.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from labstand.errors import ExitCode
from labstand.interrupts import Interrupt, Terminated, remembered_interrupt
from recordings import open_recording
from tests.run.conftest import SHORT

LABSTAND = [sys.executable, "-m", "labstand"]


def _after_file(path: Path, proc: subprocess.Popen[str], extra_s: float) -> None:
    deadline = time.monotonic() + 60
    while not path.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(extra_s)


def test_sigterm_stops_a_run_in_order_and_says_so(tmp_path: Path) -> None:
    out = tmp_path / "term.mcap"
    proc = subprocess.Popen(
        [*LABSTAND, "run", *SHORT, "-o", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        _after_file(out, proc, 1.0)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == ExitCode.TERMINATED, err
    last = err.strip().splitlines()[-1]
    assert last.startswith("labstand: terminated: SIGTERM at "), last
    assert "controlled stop" in last and "Ctrl-C" not in last
    rec = open_recording(out)
    stops = rec.events().query("kind == 'stop'")["text"].tolist()
    assert stops and stops[0].startswith("SIGTERM at ")


def test_sigterm_ends_play_with_one_line(tmp_path: Path) -> None:
    s11 = tmp_path / "s11.mcap"
    subprocess.run([*LABSTAND, "simulate", "--situation", "11", "-o", str(s11)], check=True)
    proc = subprocess.Popen(
        [*LABSTAND, "play", str(s11), "--loop", "--no-wait", "--foxglove", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        for line in proc.stdout:  # serving: a pass has been played
            if line.startswith("  pass "):
                break
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == ExitCode.TERMINATED, err
    assert err.strip().splitlines() == ["labstand: terminated (SIGTERM)"], err


def test_a_remembered_sigterm_is_raised_as_terminated() -> None:
    event: Interrupt
    try:
        with remembered_interrupt(raise_now=False) as event:
            signal.raise_signal(signal.SIGTERM)
            assert event.is_set() and event.terminated
            event.raise_it()
    except Terminated:
        pass
    else:
        raise AssertionError("no Terminated raised")
