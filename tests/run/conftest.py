"""Fixtures of the ``labstand run`` tests: leak checks, the CLI in-process and as a process.

The end-to-end and fault tests use the real parts: ``labstand run`` starts the real
``labstand stand-sim`` child (Modbus TCP on 127.0.0.1, gauges on a raw pty) and talks to
it with the real drivers. A fixture fails any test that leaves a thread, a file
descriptor or a child process behind.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from labstand.cli import main
from tests.hardware_sim.leakcheck import gone, no_leaks

__all__ = ["no_leaks"]

#: A short trapezoidal run (0.2 s rest, 2 cycles at 1 Hz, 0.5 s rest: 2.7 s).
SHORT = [
    "--backend", "sim", "--signal", "trapezoidal", "--amplitude-mm", "20",
    "--frequency-hz", "1", "--cycles", "2", "--dwell-start-s", "0.2", "--dwell-end-s", "0.5",
]  # fmt: skip


@dataclass
class Outcome:
    """What ``labstand`` returned and printed."""

    code: int
    out: str
    err: str

    @property
    def last_error_line(self) -> str:
        lines = [line for line in self.err.splitlines() if line.strip()]
        return lines[-1] if lines else ""


def labstand_process(*args: str | Path, timeout_s: float = 120.0) -> Outcome:
    """Run ``python -m labstand ARGS`` as a child process (its own signals and stdio)."""
    done = subprocess.run(
        [sys.executable, "-m", "labstand", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout_s,
        check=False,
    )
    return Outcome(done.returncode, done.stdout, done.stderr)


@pytest.fixture
def labstand(capsys: pytest.CaptureFixture[str]) -> Callable[..., Outcome]:
    """Run ``labstand ARGS`` in this process."""

    def call(*args: str) -> Outcome:
        code = main([str(a) for a in args])
        captured = capsys.readouterr()
        return Outcome(code, captured.out, captured.err)

    return call


def wait_for(predicate: Callable[[], object], timeout_s: float, what: str) -> None:
    """Poll ``predicate`` every 20 ms until it is true; fail after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s:g} s waiting for {what}")
        time.sleep(0.02)


@pytest.fixture
def ctrl_c() -> Iterator[Callable[[Path, float, int], None]]:
    """``ctrl_c(recording, after_s, presses)``: SIGINT to this process once the run records.

    A thread waits until the recording file exists, ``after_s`` more, then sends
    ``presses`` SIGINTs 5 ms apart (labstand's handler runs in the main thread; the
    simulated drive's controlled stop takes only ≈ 10 ms, so a person's slower second
    press would find it already at rest).
    """
    threads: list[threading.Thread] = []

    def arm(recording: Path, after_s: float, presses: int = 1) -> None:
        def fire() -> None:
            deadline = time.monotonic() + 30.0
            while not recording.exists() and time.monotonic() < deadline:
                time.sleep(0.02)
            time.sleep(after_s)
            for _ in range(presses):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.005)

        thread = threading.Thread(target=fire, name="test ctrl-c", daemon=True)
        thread.start()
        threads.append(thread)

    yield arm
    for thread in threads:
        thread.join(35.0)


class RunProcess:
    """``python -m labstand run ...`` as a child process, its endpoints read from stdout."""

    def __init__(self, args: list[str]) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "labstand", "run", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.lines: list[str] = []
        self.sim_pid = 0
        self.modbus_port = 0

    def wait_endpoints(self, timeout_s: float = 60.0) -> None:
        """Read stdout until the line naming the simulated stand's pid and port."""
        assert self.process.stdout is not None
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            line = self.process.stdout.readline()
            if not line:
                break
            self.lines.append(line)
            found = re.search(r"\(pid (\d+)\): drive tcp://127\.0\.0\.1:(\d+)", line)
            if found:
                self.sim_pid, self.modbus_port = int(found[1]), int(found[2])
                return
        pytest.fail(f"no simulated-stand line from labstand run: {''.join(self.lines)}")

    def finish(self, timeout_s: float = 30.0) -> Outcome:
        """Wait for the exit; everything it printed."""
        out, err = self.process.communicate(timeout=timeout_s)
        return Outcome(self.process.returncode, "".join(self.lines) + out, err)

    def kill(self) -> None:
        """Make sure it is gone (for the fixture's cleanup)."""
        if self.process.poll() is None:
            self.process.kill()
        self.process.communicate(timeout=10)


@pytest.fixture
def run_process() -> Iterator[Callable[[list[str]], RunProcess]]:
    """Start ``labstand run`` as a process; killed and reaped at the end of the test."""
    started: list[RunProcess] = []

    def start(args: list[str]) -> RunProcess:
        proc = RunProcess(args)
        started.append(proc)
        return proc

    yield start
    for proc in started:
        proc.kill()
        if proc.sim_pid:
            deadline = time.monotonic() + 10.0
            while not gone(proc.sim_pid) and time.monotonic() < deadline:
                time.sleep(0.05)
            if not gone(proc.sim_pid):
                os.kill(proc.sim_pid, signal.SIGKILL)
                pytest.fail(f"the simulated stand {proc.sim_pid} outlived labstand run")
