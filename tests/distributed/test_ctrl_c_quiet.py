"""Ctrl-C at a terminal reaches the workers too (the whole process group): the run still
ends in one line, ``labstand: interrupted`` (130), with no worker's traceback and no
Dask warning, and leaves no process behind."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path


def test_ctrl_c_to_the_process_group_is_one_line(manifest: Path) -> None:
    process = subprocess.Popen(
        [sys.executable, "-m", "labstand", "diagnose", "--campaigns", str(manifest),
         "--workers", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own group, as a shell's foreground job
    )  # fmt: skip
    assert process.stderr is not None
    first = process.stderr.readline()  # the cluster is up, the campaigns are running
    assert "local cluster: 2 worker process(es)" in first, first
    time.sleep(1.0)
    os.killpg(process.pid, signal.SIGINT)  # what the terminal does on Ctrl-C
    _, rest = process.communicate(timeout=60)
    err = first + rest
    assert process.returncode == 130, err
    lines = err.splitlines()
    assert lines[-1] == "labstand: interrupted", err
    assert "Traceback" not in err and "WARNING" not in err and "ERROR" not in err, err
    assert all(line.startswith("labstand") for line in lines), err
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:  # the workers are gone with the run
        try:
            os.killpg(process.pid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.1)
    raise AssertionError("processes of the run's group are still alive")
