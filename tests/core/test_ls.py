"""``labstand ls``: a folder's recordings from their metadata alone, filtered."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from labstand.cli import main


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("day")
    for name, who, extra in (
        ("a.mcap", ["--operator", "ana", "--sample", "F-07", "--tag", "warm"], []),
        ("b.h5", ["--operator", "bo", "--sample", "F-07"], ["--mass-kg", "3.096"]),
        ("c.mcap", ["--operator", "ana", "--sample", "F-08"], ["--situation", "10"]),
    ):
        situation = [] if "--situation" in extra else ["--situation", "11"]
        assert main(["simulate", *situation, *extra, *who, "-o", str(root / name)]) == 0
    assert main(["convert", str(root / "a.mcap"), str(root / "a.parquet")]) == 0
    assert main(["convert", str(root / "b.h5"), str(root / "b.csv")]) == 0
    (root / "broken.mcap").write_bytes(b"\x89MCAP0\r\n and then nothing")
    (root / "notes.txt").write_text("not a recording\n")
    return root


def ls(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "labstand", "ls", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def test_the_table_lists_every_recording(folder: Path) -> None:
    done = ls(folder)
    assert done.returncode == 0 and done.stderr == ""
    lines = done.stdout.splitlines()
    assert lines[0].split()[:4] == ["date", "(UTC)", "duration", "signal"]
    assert len(lines) == 1 + 6  # five recordings and the broken one; no notes.txt
    row = next(line for line in lines if line.split()[-1:] != [] and "b.h5" in line)
    assert "3.096 kg" in row and " bo " in row and "F-07" in row and "4.0 s" in row
    assert any("broken.mcap" in line and "unreadable" in line for line in lines)


def test_json_and_filters(folder: Path) -> None:
    rows = json.loads(ls(folder, "--json").stdout)
    by_name = {Path(r["path"]).name: r for r in rows}
    a = by_name["a.parquet"]
    assert (a["operator"], a["sample"], a["tags"], a["duration_s"]) == (
        "ana",
        "F-07",
        ["warm"],
        4.0,
    )
    assert a["run_id"] == by_name["a.mcap"]["run_id"]  # a conversion keeps the run's id
    assert by_name["c.mcap"]["signal"]["situation"] == "10"
    assert by_name["b.csv"]["mass_kg"] == 3.096

    def names(*f: str) -> list[str]:
        return sorted(Path(r["path"]).name for r in json.loads(ls(folder, "--json", *f).stdout))

    assert names("--operator", "ANA") == ["a.mcap", "a.parquet", "c.mcap"]
    assert names("--operator", "ana", "--sample", "F-07") == ["a.mcap", "a.parquet"]
    assert names("--tag", "warm") == ["a.mcap", "a.parquet"]
    assert names("--tag", "warm", "--tag", "cold") == []


def test_it_reads_metadata_only(folder: Path) -> None:
    code = (
        "import sys; from labstand.cli import main; "
        f"assert main(['ls', {str(folder)!r}, '--json']) == 0; "
        "print(sorted(m for m in ('recordings.mcap_reader', 'recordings.tables', "
        "'recordings.csvio', 'pandas', 'numba') if m in sys.modules), file=sys.stderr)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stderr.strip() == "[]"  # no stream reader, no pandas, no model


def test_a_missing_path_is_one_line_and_exit_2(tmp_path: Path) -> None:
    done = ls(tmp_path / "nope")
    assert (
        done.returncode == 2
        and done.stderr == f"labstand: error: no such file: {tmp_path / 'nope'}\n"
    )


def test_import_stores_the_operator_and_tags(folder: Path, tmp_path: Path) -> None:
    out = tmp_path / "imported.h5"
    argv = ["import", str(folder / "b.csv"), "--operator", "zoe", "--tag", "imported"]
    assert main([*argv, "-o", str(out)]) == 0
    (row,) = json.loads(ls(out, "--json").stdout)
    assert (row["operator"], row["sample"], row["tags"]) == ("zoe", "F-07", ["imported"])
