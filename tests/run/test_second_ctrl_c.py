"""A second Ctrl-C after the controlled stop is done: the end and the recording say what
the terminal said ("disabling the drive at once"), not a plain "controlled stop"."""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable
from pathlib import Path

from labstand.errors import ExitCode
from recordings import open_recording
from tests.run.conftest import SHORT, Outcome


def test_a_slow_second_press_is_an_immediate_disable(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    out = tmp_path / "twice.mcap"

    def presses() -> None:  # a person's pace: the simulated drive is at rest by the second
        deadline = time.monotonic() + 60.0
        while not out.exists() and time.monotonic() < deadline:
            time.sleep(0.02)
        time.sleep(1.0)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.12)
        os.kill(os.getpid(), signal.SIGINT)

    thread = threading.Thread(target=presses, name="test ctrl-c twice", daemon=True)
    thread.start()
    result = labstand("run", *SHORT, "-o", out)
    thread.join(65.0)
    assert result.code == ExitCode.INTERRUPTED, result.err
    line = result.last_error_line
    assert line.startswith("labstand: interrupted: Ctrl-C") and "immediate disable" in line, line
    events = open_recording(out).events()
    kinds = list(events["kind"])
    assert "estop" in kinds, kinds
    estop = str(events["text"].iloc[kinds.index("estop")])
    assert estop.endswith("immediate disable"), estop
