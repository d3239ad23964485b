"""The simulated stand as a child process: ``labstand stand-sim --json`` started and stopped.

``labstand run --backend sim`` starts the simulated stand this way (a process of its own
with its own session, so Ctrl-C reaches the run alone, which then stops in order); tests
and benchmarks do too.
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import subprocess
import sys
import time
from collections.abc import Sequence
from types import TracebackType
from typing import Any, Self

__all__ = ["StandProcess", "StandStartError", "wait_exit"]


class StandStartError(RuntimeError):
    """The simulated stand's process did not come up (its stderr in the message)."""


class StandProcess:
    """``labstand stand-sim --json`` as a child process.

    ``with StandProcess(["--mass-kg", "3.096"]) as sim: sim.endpoints["modbus"]`` starts
    it, waits for its ready line and stops it (SIGTERM, then SIGKILL) on exit. The first
    start in a fresh checkout compiles the model's kernels (≈ 10 s, more on a busy
    machine) before the ready line, hence the generous time-out.
    """

    def __init__(self, extra_args: Sequence[str] = (), start_timeout_s: float = 120.0) -> None:
        self.args = [
            sys.executable,
            "-m",
            "labstand",
            "stand-sim",
            "--json",
            "--parent-pid",
            str(os.getpid()),
            *extra_args,
        ]
        self._timeout = start_timeout_s
        self.process: subprocess.Popen[str] | None = None
        self.endpoints: dict[str, Any] = {}
        self.stopped: dict[str, Any] = {}  # the child's last line, once it has exited

    def start(self) -> dict[str, Any]:
        """Start the child and return its ready line (endpoints)."""
        # A session of its own: Ctrl-C at the terminal reaches the parent alone, which
        # then stops the run in order while the simulated stand keeps serving.
        self.process = subprocess.Popen(
            self.args,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        assert self.process.stdout is not None
        ready, _, _ = select.select([self.process.stdout], [], [], self._timeout)
        line = self.process.stdout.readline() if ready else ""
        if not line:
            if ready:  # its stdout closed: the child is ending, and its stderr says why
                with contextlib.suppress(subprocess.TimeoutExpired):
                    self.process.wait(self._timeout)
            why = self._stderr()  # read before stop(), which closes the pipes
            self.stop()
            raise StandStartError(f"the simulated stand did not start: {why}")
        self.endpoints = json.loads(line)
        return self.endpoints

    def _stderr(self) -> str:
        """The child's last line on stderr, without its own ``labstand: error:`` prefix."""
        if self.process is None or self.process.stderr is None or self.process.poll() is None:
            return f"no ready line within {self._timeout:g} s"
        lines = [x.strip() for x in self.process.stderr.read().splitlines() if x.strip()]
        last = lines[-1] if lines else f"it exited with code {self.process.returncode}"
        for prefix in ("labstand: error: ", "labstand: refused: "):
            last = last.removeprefix(prefix)
        return last[-2000:]

    def stop(self, timeout_s: float = 5.0) -> int | None:
        """SIGTERM and wait; SIGKILL if it does not exit in time. Returns the exit code."""
        p = self.process
        if p is None:
            return None
        if p.poll() is None:
            p.terminate()
            try:
                p.wait(timeout_s)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout_s)
        if p.stdout is not None and not p.stdout.closed:
            for line in p.stdout.read().splitlines():
                with contextlib.suppress(ValueError):
                    self.stopped = json.loads(line)
        for stream in (p.stdout, p.stderr):
            if stream is not None:
                stream.close()
        return p.returncode

    def __enter__(self) -> Self:
        self.start()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()


def wait_exit(process: subprocess.Popen[Any], timeout_s: float) -> int | None:
    """The exit code once the process ends within timeout_s, else None."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if (code := process.poll()) is not None:
            return code
        time.sleep(0.02)
    return None
