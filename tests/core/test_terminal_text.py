"""Text a recording carries reaches the terminal escaped: no escape sequence from a file."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

from tests.fuzz import corpus

EXE = Path(sys.executable).with_name("labstand")
NASTY = "title\x1b]0;pwned\x07\x1b[31mred\rback"


def _nasty_recording(tmp_path: Path) -> Path:
    from recordings import make_metadata, open_recording, open_writer

    seed = corpus.write_seeds(tmp_path)[".mcap"]
    rec = open_recording(seed)
    meta = dataclasses.replace(make_metadata({}, "sim", operator_note=NASTY), host=NASTY)
    path = tmp_path / "nasty.mcap"
    with open_writer(path, meta) as w:
        w.write_event(0, "note", NASTY)
        w.write_gauges(rec.gauges)
        w.write_event(int(rec.gauges["t_ns"][-1]), "stop", NASTY)
    return path


def test_info_and_cat_escape_what_the_file_says(tmp_path: Path) -> None:
    path = _nasty_recording(tmp_path)
    for args in (["info", str(path)], ["cat", str(path), "--events"]):
        res = subprocess.run([str(EXE), *args], capture_output=True, text=True, check=True)
        assert "\x1b" not in res.stdout and "\x07" not in res.stdout and "\r" not in res.stdout
        # (cat --events makes the CR a space: whitespace)
        assert "title\\x1b]0;pwned\\x07\\x1b[31mred" in res.stdout, res.stdout
