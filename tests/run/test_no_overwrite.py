"""A repeated ``labstand run -o same.mcap`` keeps the first recording byte for byte."""

from __future__ import annotations

import hashlib
from pathlib import Path

from labstand.errors import ExitCode
from recordings import open_recording
from tests.run.conftest import SHORT, labstand_process


def test_a_repeated_run_keeps_the_first_recording(tmp_path: Path) -> None:
    out = tmp_path / "same.mcap"
    first = labstand_process("run", *SHORT, "-o", out)
    assert first.code == ExitCode.OK, first.err
    digest = hashlib.sha256(out.read_bytes()).hexdigest()
    again = labstand_process("run", *SHORT, "-o", out)
    assert again.code == ExitCode.USAGE
    assert again.err == (
        f"labstand: error: {out}: exists; nothing written (give --force to replace it)\n"
    )
    assert again.out == ""  # refused before the simulated stand started or the drive moved
    assert hashlib.sha256(out.read_bytes()).hexdigest() == digest
    assert sorted(p.name for p in tmp_path.iterdir()) == ["same.mcap"]
    forced = labstand_process("run", *SHORT, "-o", out, "--force")
    assert forced.code == ExitCode.OK, forced.err
    assert open_recording(out).metadata.start_time_utc != ""
    assert hashlib.sha256(out.read_bytes()).hexdigest() != digest
