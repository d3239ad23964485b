"""The CLI's manners: a closed pipe ends quietly, usage errors fit one line, -v anywhere."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

EXE = Path(sys.executable).with_name("labstand")


def test_a_closed_pipe_ends_quietly() -> None:
    # `labstand model effects --json | head -1`, several times: the race between the
    # writer and the reader's exit must never end in a traceback or exit 1.
    for _ in range(5):
        with subprocess.Popen(
            [EXE, "model", "effects", "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE
        ) as proc:
            assert proc.stdout is not None and proc.stderr is not None
            proc.stdout.readline()
            proc.stdout.close()  # the reader is gone
            err = proc.stderr.read().decode()
            assert proc.wait(timeout=60) == 0, err
            assert err == ""


def test_a_usage_error_is_one_line_with_a_hint() -> None:
    res = subprocess.run(
        [EXE, "simulate", "--situation", "11", "--bogus"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert "--bogus" in lines[0] and "see 'labstand simulate --help'" in lines[0]


def test_verbose_is_taken_after_the_command_too() -> None:
    before = subprocess.run(
        [EXE, "-v", "model", "modes", "--json"], capture_output=True, check=True
    )
    after = subprocess.run([EXE, "model", "modes", "--json", "-v"], capture_output=True, check=True)
    assert before.returncode == after.returncode == 0
    assert before.stdout == after.stdout
