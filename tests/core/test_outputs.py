"""Nothing is overwritten: every command that writes refuses an existing output (exit 2,
one line naming it) unless ``--force``, before it does any work, and refuses a missing
parent folder the same way (nothing creates it)."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

PRECIOUS = b"an earlier day's measurement\n"


def labstand(*args: str | Path, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "labstand", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        cwd=cwd,
    )


@pytest.fixture(scope="module")
def rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("rec")
    path = folder / "s11.mcap"
    assert labstand("simulate", "--situation", "11", "-o", path).returncode == 0
    assert labstand("convert", path, folder / "s11.csv").returncode == 0
    (folder / "campaigns.toml").write_text(
        f'[campaign.a]\nrecordings = ["{path}"]\nmass_kg = 8.131\n'
    )
    return path


def _commands(rec: Path, out: Path) -> list[list[str | Path]]:
    """Every command that writes, with ``out`` as what it writes (file outputs)."""
    return [
        ["simulate", "--situation", "11", "-o", out.with_suffix(".csv")],
        ["simulate", "--situation", "11", "--plot", out.with_suffix(".png")],
        ["convert", rec, out.with_suffix(".h5")],
        ["convert", rec, out.with_suffix(".parquet")],
        ["trim", rec, "--end", "1", "-o", out.with_suffix(".mcap")],
        ["recover", rec, "-o", out.with_suffix(".mcap")],
        ["import", rec.with_suffix(".csv"), "-o", out.with_suffix(".h5")],
        ["replay", rec, "--plot", out.with_suffix(".png")],
        ["compare", rec, rec, "--plot", out.with_suffix(".png")],
        ["diagnose-check", "-o", out.with_suffix(".json")],
    ]


def _target(argv: list[str | Path]) -> Path:
    return next(a for a in argv if isinstance(a, Path) and a.name.startswith("out"))


@pytest.mark.parametrize("i", range(10))
def test_an_existing_output_is_refused_and_kept(rec: Path, tmp_path: Path, i: int) -> None:
    argv = _commands(rec, tmp_path / "out")[i]
    target = _target(argv)
    target.write_bytes(PRECIOUS)
    done = labstand(*argv)
    assert done.returncode == 2, done.stderr
    assert done.stderr == (
        f"labstand: error: {target}: exists; nothing written (give --force to replace it)\n"
    ) or done.stderr.startswith(f"labstand: error: --plot {target}: exists;")
    assert target.read_bytes() == PRECIOUS
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]  # no stub either


@pytest.mark.parametrize("i", range(10))
def test_a_missing_parent_folder_is_refused_not_created(rec: Path, tmp_path: Path, i: int) -> None:
    argv = _commands(rec, tmp_path / "absent" / "out")[i]
    done = labstand(*argv)
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.splitlines()) == 1
    assert f"cannot write: no such folder {tmp_path / 'absent'}" in done.stderr
    assert not (tmp_path / "absent").exists()


def test_force_replaces(rec: Path, tmp_path: Path) -> None:
    target = tmp_path / "out.h5"
    target.write_bytes(PRECIOUS)
    done = labstand("convert", rec, target, "--force")
    assert done.returncode == 0, done.stderr
    assert target.read_bytes()[:8] == b"\x89HDF\r\n\x1a\n"


@pytest.mark.parametrize("option", ["--report", "--results"])
def test_report_folders_are_checked_before_the_work(rec: Path, tmp_path: Path, option: str) -> None:
    a_file = tmp_path / "afile"
    a_file.write_bytes(PRECIOUS)
    source = ["--campaigns", rec.with_name("campaigns.toml")] if option == "--results" else [rec]
    for target, says in (
        (a_file, f"{option} {a_file}: is a file, not a folder"),
        (tmp_path / "nonexist" / "rep", f"cannot write: no such folder {tmp_path / 'nonexist'}"),
        (tmp_path, f"{option} {tmp_path}: exists; nothing written (give --force"),
    ):
        start = time.monotonic()
        done = labstand("diagnose", *source, option, target)
        assert done.returncode == 2 and says in done.stderr, done.stderr
        assert len(done.stderr.splitlines()) == 1
        assert time.monotonic() - start < 15  # refused at once, not after the fitting
    assert a_file.read_bytes() == PRECIOUS and not (tmp_path / "nonexist").exists()
