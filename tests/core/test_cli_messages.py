"""What the commands say: the user's paths (never a temporary name), each repair once,
and one result per recording for ``replay`` of several."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from labstand.cli import main

EXE = Path(sys.executable).with_name("labstand")


@pytest.mark.parametrize("suffix", [".csv", ".mcap", ".h5"])
def test_a_write_into_a_missing_folder_names_the_users_path(
    tmp_path: Path, suffix: str, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "absent" / f"x{suffix}"
    assert main(["simulate", "--situation", "11", "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert err == f"labstand: error: {target}: cannot write: no such folder {target.parent}\n"
    assert not (tmp_path / "absent").exists()


def test_a_write_below_a_file_names_the_users_path(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a_file = tmp_path / "s11.csv"
    a_file.write_text("not a folder\n")
    target = a_file / "x.h5"
    assert main(["simulate", "--situation", "11", "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert err == f"labstand: error: {target}: cannot write: {a_file} is not a folder\n"


def test_convert_and_recover_name_the_users_target(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = tmp_path / "s11.mcap"
    assert main(["simulate", "--situation", "11", "-o", str(rec)]) == 0
    capsys.readouterr()
    for argv, target in (
        (["convert", str(rec), str(tmp_path / "no" / "y.h5")], tmp_path / "no" / "y.h5"),
        (["recover", str(rec), "-o", str(tmp_path / "no" / "y.mcap")], tmp_path / "no" / "y.mcap"),
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"labstand: error: {target}: cannot write") and ".part" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s11.mcap"]  # no stub left


def test_recover_reports_each_repair_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    whole = tmp_path / "whole.mcap"
    assert main(["simulate", "--situation", "11", "-o", str(whole)]) == 0
    data = whole.read_bytes()
    broken = tmp_path / "broken.mcap"
    broken.write_bytes(data[: len(data) * 2 // 3])  # a writer killed mid-run
    # the console script, as a user sees it: stdout and stderr on one terminal
    res = subprocess.run(
        [EXE, "recover", str(broken), "-o", str(tmp_path / "fixed.mcap")],
        capture_output=True,
        text=True,
        check=True,
    )
    both = res.stdout + res.stderr
    assert both.count("the file is truncated") == 1, both
    assert main(["info", str(tmp_path / "fixed.mcap")]) == 0


def test_replay_of_several_recordings_one_block_each(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a, b = tmp_path / "s11.csv", tmp_path / "s10.csv"
    assert main(["simulate", "--situation", "11", "-o", str(a)]) == 0
    assert main(["simulate", "--situation", "10", "-o", str(b)]) == 0
    capsys.readouterr()
    png = tmp_path / "r.png"
    assert main(["replay", str(a), str(b), "--json", "--plot", str(png)]) == 0
    results = json.loads(capsys.readouterr().out)
    assert [r["recording"] for r in results] == [str(a), str(b)]
    assert [Path(r["plot"]).name for r in results] == ["r-s11.png", "r-s10.png"]
    assert all(Path(r["plot"]).read_bytes()[:4] == b"\x89PNG" for r in results)
    assert not png.exists()
    assert all(r["channels"]["u"]["R"] > 0.9999 for r in results)
    assert main(["replay", str(a), str(b)]) == 0
    text = capsys.readouterr().out
    assert text.count("Replay of ") == 2 and text.index(str(a)) < text.index(str(b))
    assert main(["replay", str(a), "--json"]) == 0  # one recording: one object, as before
    assert json.loads(capsys.readouterr().out)["recording"] == str(a)


def test_replay_plots_of_recordings_with_one_stem_do_not_overwrite(tmp_path: Path) -> None:
    from labstand.commands.replay import plot_paths

    paths = plot_paths(tmp_path / "r.png", [Path("a/s11.mcap"), Path("b/s11.mcap"), Path("c.h5")])
    assert [p.name for p in paths] == ["r-s11-1.png", "r-s11-2.png", "r-c.png"]


def test_table1_gives_every_r_with_six_decimals(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = tmp_path / "s11.csv"
    assert main(["simulate", "--situation", "11", "-o", str(rec)]) == 0
    capsys.readouterr()
    assert main(["table1", str(rec)]) == 0
    row = capsys.readouterr().out.splitlines()[-1].split("|")[1:-1]
    r_cells = [c.strip() for c in row[3:7]]  # R(u) and R(F) for both parameter sets
    assert all(len(c.split(".")[1]) == 6 for c in r_cells), r_cells


@pytest.mark.parametrize("suffix", [".mcap", ".h5"])
def test_a_writers_data_check_names_the_users_path(tmp_path: Path, suffix: str) -> None:
    import numpy as np

    from recordings.convert import write_streams
    from recordings.errors import InvalidDataError
    from recordings.schema import GAUGES_DTYPE, make_metadata
    from sim.config import default_config

    meta = make_metadata(default_config().to_dict(), "simulate")
    gauges = np.zeros(4, GAUGES_DTYPE)
    gauges["t_ns"] = np.arange(4) * 500_000
    gauges["seq"] = np.arange(4)
    target = tmp_path / f"x{suffix}"
    with pytest.raises(InvalidDataError) as exc:
        write_streams(target, meta, gauges, events=[(0, "", "an event without a kind")])
    assert str(exc.value).startswith(f"{target}: ") and ".part" not in str(exc.value)
    assert list(tmp_path.iterdir()) == []
