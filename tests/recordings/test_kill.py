"""kill -9 in the middle of a recording loses at most the last second (both formats)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from labstand.cli import main
from recordings import TruncatedRecordingError, open_recording

WORKER = Path(__file__).with_name("kill_worker.py")


def _run_and_kill(out: Path, run_s: float) -> int:
    """Start the worker, kill -9 it after ``run_s``; the last t_ns it reported written."""
    proc = subprocess.Popen(
        [sys.executable, str(WORKER), str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    lines: list[str] = []
    started = threading.Event()

    def drain() -> None:  # keep the pipe empty so the worker never blocks on print
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.append(line)
            started.set()

    reader = threading.Thread(target=drain, daemon=True)
    reader.start()
    try:
        assert started.wait(30), "the worker did not start"
        time.sleep(run_s)  # the kill test's own timing: let it write, then kill it
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
        reader.join(10)
        if proc.stderr is not None:
            proc.stderr.close()
        if proc.stdout is not None:
            proc.stdout.close()
    assert proc.returncode == -signal.SIGKILL
    claims = [int(line.split()[1]) for line in lines if line.startswith("G ")]
    assert claims, "the worker wrote nothing before it was killed"
    return claims[-1]


@pytest.mark.parametrize("suffix", [".mcap", ".h5"])
def test_kill_9_loses_at_most_one_second(tmp_path: Path, suffix: str, capsys) -> None:
    broken = tmp_path / f"broken{suffix}"
    written_ns = _run_and_kill(broken, run_s=2.0)
    assert written_ns > 5e9  # it got well past the first seconds of data

    with pytest.raises(TruncatedRecordingError, match="labstand recover"):
        open_recording(broken)

    fixed = tmp_path / f"fixed{suffix}"
    assert main(["recover", str(broken), "-o", str(fixed)]) == 0
    assert "recovered" in capsys.readouterr().out

    rec = open_recording(fixed)
    g = rec.gauges
    end_ns = int(g["t_ns"][-1])
    assert end_ns >= written_ns - 1_000_000_000, (end_ns, written_ns)
    print(f"lost {(written_ns - end_ns) / 1e9:.3f} s of {written_ns / 1e9:.1f} s")
    # contiguous from the first sample: nothing lost inside, values as written
    assert np.array_equal(g["seq"], np.arange(len(g)))
    assert np.array_equal(g["t_ns"], np.arange(len(g)) * 500_000)
    assert np.allclose(g["x_mm"], np.sin(np.arange(len(g)) * 1e-3), rtol=0, atol=0)
    assert rec.lost_samples == 0
    # the command stream survived as far (same clock, same blocks)
    assert int(rec.command["t_ns"][-1]) >= written_ns - 1_000_000_000
    assert len(rec.drive) > 0
    kinds = rec.events()["kind"].tolist()
    assert kinds[0] == "start" and kinds[-1] == "repair"
    assert rec.metadata.operator_note == "kill test"
