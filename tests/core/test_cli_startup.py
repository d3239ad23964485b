"""Start-up: the parser is built without the heavy modules; only the chosen command loads.

Speed itself is measured in benchmarks/bench_startup.py (docs/benchmarks.md); these tests
check the cause of slowness that can regress silently: a heavy import at parser time.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from labstand.cli import COMMANDS, _subparser, build_parser, command_module, main

EXE = Path(sys.executable).with_name("labstand")
HEAVY = ("numba", "scipy", "pandas", "matplotlib", "h5py", "mcap", "pymodbus", "nptdms", "serial")

# In a fresh interpreter: for the top-level --help and every `CMD --help`, the heavy root
# packages that were imported (cumulatively, in order, so a culprit is named).
_PROBE = """
import contextlib, io, json, sys
from labstand.cli import COMMANDS, main
heavy = set(json.loads(sys.argv[1]))
seen = {}
for words in [[]] + [[name] for name in COMMANDS]:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):
        main([*words, "--help"])
    seen[" ".join(words) or "--help"] = sorted(
        {m.split(".")[0] for m in sys.modules} & heavy
    )
print(json.dumps(seen))
"""


def test_help_of_every_command_imports_no_heavy_module() -> None:
    res = subprocess.run(
        [sys.executable, "-c", _PROBE, json.dumps(HEAVY)],
        capture_output=True,
        text=True,
        check=True,
    )
    seen = json.loads(res.stdout)
    assert list(seen) == ["--help", *COMMANDS]
    assert {words: mods for words, mods in seen.items() if mods} == {}


def test_console_script_help_loads_no_heavy_module() -> None:
    # the installed entry point, as a user runs it; -X importtime lists every import
    res = subprocess.run(
        [sys.executable, "-X", "importtime", str(EXE), "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "diagnose-check" in res.stdout
    imported = {line.split("|")[-1].strip().split(".")[0] for line in res.stderr.splitlines()}
    assert not imported & set(HEAVY), sorted(imported & set(HEAVY))
    assert "labstand.commands" not in res.stderr  # not one command module for the list


@pytest.mark.parametrize("name", list(COMMANDS))
def test_each_table_entry_is_its_modules_full_command(name: str) -> None:
    # the table's name, its module, and the parser that module registers agree; the other
    # commands are stubs without options
    parser = build_parser(name)
    full = _subparser(parser, name)
    assert full is not None
    assert full.get_default("func") is not None or full._subparsers is not None  # model: nested
    assert command_module(name).startswith("labstand.commands.")
    others = [n for n in COMMANDS if n != name]
    stub = _subparser(parser, others[0])
    assert stub is not None and [a.dest for a in stub._actions] == []


def test_the_top_level_help_lists_every_command_with_its_help() -> None:
    help_text = build_parser("").format_help()
    for name, text in COMMANDS.items():
        assert name in help_text
        assert text.split()[0] in help_text


def test_a_mistyped_command_is_refused_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["simulat", "--situation", "11"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "invalid choice: 'simulat'" in err and "diagnose" in err


def test_diagnose_check_refuses_an_unknown_class_before_running(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["diagnose-check", "--effects", "fibre_viscoelastic", "bogus"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'bogus'" in err and "fibre_viscoelastic" in err


@pytest.mark.parametrize(
    "package", ["labstand", "drivers", "recordings", "sim", "sim.effects", "sim.hardware"]
)
def test_importing_a_package_loads_no_heavy_module(package: str) -> None:
    # their re-exports are lazy (PEP 562): `import sim.errors` must not pay for the model
    probe = (
        f"import sys, {package}\n"
        f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))"
    )
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert res.stdout.strip() == "[]"


def test_lazy_re_exports_are_the_real_objects() -> None:
    import recordings
    import sim
    import sim.effects
    from recordings.recording import open_recording
    from sim.effects.registry import EFFECTS
    from sim.model import Model

    assert sim.Model is Model and recordings.open_recording is open_recording
    assert sim.effects.EFFECTS is EFFECTS
    assert recordings.csvio.read_csv is not None  # a submodule, imported on first use
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        _ = sim.Nope  # type: ignore[attr-defined]


def test_version_goes_to_stdout() -> None:
    res = subprocess.run([EXE, "--version"], capture_output=True, text=True, check=True)
    assert res.stdout.startswith("labstand ") and res.stderr == ""


def test_info_reads_an_mcap_without_the_model_or_other_formats(tmp_path: Path) -> None:
    rec = tmp_path / "s11.mcap"
    assert main(["simulate", "--situation", "11", "-o", str(rec)]) == 0
    res = subprocess.run(
        [sys.executable, "-X", "importtime", str(EXE), "info", str(rec)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "8001 samples" in res.stdout
    imported = {line.split("|")[-1].strip().split(".")[0] for line in res.stderr.splitlines()}
    assert imported & set(HEAVY) == {"mcap"}  # its own reader, nothing else heavy


def test_short_version_flag() -> None:
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "labstand", "-V"], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0 and done.stdout.startswith("labstand ")
