"""Every command with bad inputs: one line on stderr, the README's exit code, no
traceback, no errno text and no library repr (0x... addresses, <pymodbus ...>)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from labstand.errors import ExitCode

USAGE, FAILURE, REFUSED = ExitCode.USAGE, ExitCode.FAILURE, ExitCode.REFUSED

#: (arguments, exit code, what the line says); REC is a good recording, DIR a folder, OUT
#: a path that does not exist yet, STAND a stand file whose drive nobody answers.
TABLE: list[tuple[str, int, str]] = [
    ("", USAGE, "the following arguments are required: COMMAND"),
    ("frobnicate", USAGE, "invalid choice: 'frobnicate'"),
    ("info REC --bogus", USAGE, "unrecognized arguments: --bogus"),
    ("info nope.mcap", USAGE, "no such file: nope.mcap"),
    ("info nope", USAGE, "no such file: nope"),
    ("info DIR", USAGE, "DIR: is a folder, not a file"),
    ("info DIR.mcap", USAGE, "DIR.mcap: is a folder, not a file"),
    ("info TEXT.xyz", USAGE, "cannot read '.xyz'"),
    ("info TEXT.mcap", USAGE, "TEXT.mcap"),
    ("cat nope.h5", USAGE, "no such file: nope.h5"),
    ("cat DIR.mcap", USAGE, "DIR.mcap: is a folder, not a file"),
    ("cat REC --channels q", USAGE, "unknown channel(s) q"),
    ("cat REC --start 3 --end 1", USAGE, "must be before --end"),
    ("convert nope.mcap OUT.h5", USAGE, "no such file: nope.mcap"),
    ("convert REC OUT.xlsx", USAGE, "cannot write '.xlsx'"),
    ("convert DIR OUT.h5", USAGE, "DIR: is a folder, not a file"),
    ("trim REC -o OUT.mcap", USAGE, "give --start T and/or --end T"),
    ("trim nope.mcap --end 1 -o OUT.mcap", USAGE, "no such file: nope.mcap"),
    ("recover nope.mcap -o OUT.mcap", USAGE, "no such file: nope.mcap"),
    ("doctor nope.mcap", USAGE, "no such file: nope.mcap"),
    ("doctor DIR", USAGE, "DIR: is a folder"),
    ("doctor TEXT.mcap", USAGE, "recover cannot read it either"),
    ("ls nope", USAGE, "no such file: nope"),
    ("plot nope.mcap", USAGE, "no such file: nope.mcap"),
    ("plot REC --start 99 -o OUT.png", USAGE, "--start 99 s is outside"),
    ("plot REC -o OUT", USAGE, "cannot draw 'files without a suffix'"),
    ("completion fish", USAGE, "invalid choice: 'fish'"),
    ("import nope.csv -o OUT.mcap", USAGE, "no such file: nope.csv"),
    ("import DIR -o OUT.mcap", USAGE, "DIR: is a folder"),
    ("replay nope.mcap", USAGE, "no such file: nope.mcap"),
    ("compare REC nope.mcap", USAGE, "no such file: nope.mcap"),
    ("table1 nope.mcap", USAGE, "no such file: nope.mcap"),
    ("play nope.mcap", USAGE, "no such file: nope.mcap"),
    ("diagnose", USAGE, "no recordings given"),
    ("diagnose nope.mcap", USAGE, "no such file: nope.mcap"),
    ("diagnose --campaigns nope.toml", USAGE, "manifest: no such file: nope.toml"),
    ("diagnose REC --results OUT", USAGE, "--results goes with --campaigns"),
    ("diagnose-check --truth bogus", USAGE, "invalid choice: 'bogus'"),
    ("simulate --situation 99", USAGE, "99"),
    ("simulate --situation 11 -o OUT.xyz", USAGE, "unknown output format '.xyz'"),
    ("simulate --situation 11 --stand nope.toml", USAGE, "nope.toml"),
    ("model modes --params bogus", USAGE, "bogus"),
    ("run --backend sim --situation 11 --mass-kg -1 -o OUT.mcap", USAGE, "mass must be > 0 kg"),
    ("run --backend sim --situation 11 --mass-kg 0 -o OUT.mcap", USAGE, "mass must be > 0 kg"),
    ("run --backend bogus --situation 11 -o OUT.mcap", USAGE, "unknown backend 'bogus'"),
    ("run --backend sim --situation 11 -o OUT.csv", USAGE, "cannot record '.csv'"),
    ("run --backend sim --situation 11 -o REC", USAGE, "exists; nothing written"),
    ("run --stand STAND --yes --situation 11 -o OUT.mcap", FAILURE, "cannot connect"),
    ("run --backend sim --effect bogus --situation 11 -o OUT.mcap", USAGE, "bogus"),
    ("stand-sim --effect bogus", USAGE, "bogus"),
]


@pytest.fixture(scope="module")
def places(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("bad")
    rec = folder / "rec.mcap"
    done = subprocess.run(
        [sys.executable, "-m", "labstand", "simulate", "--situation", "11", "-o", str(rec)],
        capture_output=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    (folder / "dir").mkdir()
    (folder / "dir.mcap").mkdir()
    (folder / "text.xyz").write_text("hello\n")
    (folder / "text.mcap").write_text("hello, not an MCAP file\n")
    stand = folder / "stand.toml"
    stand.write_text('[devices]\ndrive = "tcp://127.0.0.1:1"\ngauges = "/dev/null"\n')
    return {
        "REC": rec,
        "DIR": folder / "dir",
        "TEXT": folder / "text",
        "OUT": folder / "out",
        "STAND": stand,
    }


@pytest.mark.parametrize(("words", "code", "says"), TABLE, ids=[t[0] or "-" for t in TABLE])
def test_bad_input(places: dict[str, Path], words: str, code: int, says: str) -> None:
    def place(word: str) -> str:
        for key, path in places.items():
            if word.startswith(key):
                return str(path) + word[len(key) :]
        return word

    argv = [place(w) for w in words.split()]
    done = subprocess.run(
        [sys.executable, "-m", "labstand", *argv],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        cwd=places["OUT"].parent,
    )
    assert done.returncode == code, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    line = lines[0]
    assert line.startswith("labstand"), line
    assert place(says.split(maxsplit=1)[0]) in line or says in line, line
    assert says.replace("DIR", str(places["DIR"])) in line or place(says) in line or says in line
    assert "Traceback" not in line and "[Errno" not in line, line
    assert not re.search(r"0x[0-9a-f]{6,}|<\w+(\.\w+)* (at|object) ", line), line  # no library repr
    assert not places["OUT"].exists() and not list(places["OUT"].parent.glob("*.part*"))


def test_an_unexpected_error_is_still_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import labstand.commands.info as info
    from labstand.cli import main

    def broken(args: object) -> int:
        raise KeyError("bug")

    monkeypatch.setattr(info, "run", broken)
    assert main(["info", "x.mcap"]) == ExitCode.FAILURE
    err = capsys.readouterr().err
    assert err == (
        "labstand: error: internal error (KeyError: 'bug'); -v shows where, please report it\n"
    )
