"""``labstand doctor``: says whether a recording is whole and what recover would do,
and writes nothing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from labstand.cli import main
from recordings import open_recording


def doctor(path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "labstand", "doctor", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def test_intact_damaged_and_unreadable(tmp_path: Path) -> None:
    whole = tmp_path / "whole.mcap"
    assert main(["simulate", "--situation", "11", "-o", str(whole)]) == 0
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size * 2 // 3])
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not HDF5 at all\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    ok = doctor(whole)
    assert ok.returncode == 0 and ok.stderr == ""
    assert ok.stdout == (
        f"{whole}: intact: 8001 samples, 4.000 s, 0 lost in gaps, 2 event(s); "
        "nothing for recover to do\n"
    )
    damaged = doctor(cut)
    assert damaged.returncode == 1 and damaged.stderr == ""
    lines = damaged.stdout.splitlines()
    assert lines[0].startswith(f"{cut}: damaged: {cut}: the file is truncated")
    salvaged = open_recording(cut, salvage=True, log_repairs=False)
    assert f"would keep {len(salvaged.gauges)} samples" in lines[1]
    assert 0 < len(salvaged.gauges) < 8001 and lines[2].strip().startswith("recovered:")
    unreadable = doctor(junk)
    assert unreadable.returncode == 2 and unreadable.stdout == ""
    assert (
        len(unreadable.stderr.splitlines()) == 1 and "recover cannot read it" in unreadable.stderr
    )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # nothing written
