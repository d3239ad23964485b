"""Every fuzz-found input and every command its README names, as argv templates.

``tests/fixtures/fuzz/`` holds the first corpus (README there), ``tests/fixtures/fuzz2/``
the second (its README: file → command → what happened). A case is (fixture, argv):
``{f}`` is the file, ``{out}`` a writable folder, ``{seed}`` a valid recording. The
recordings of the first corpus go through every read path, not only the ``info`` its
README names: one validation must serve them all.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

FIXTURES = Path(__file__).parents[1] / "fixtures"

#: every command that reads a recording (diagnose and play are slower to start: below)
READ_PATHS: tuple[tuple[str, ...], ...] = (
    ("info", "{f}"),
    ("cat", "{f}"),
    ("cat", "{f}", "--events"),
    ("cat", "{f}", "--start", "0.1", "--end", "0.3"),
    ("trim", "{f}", "-o", "{out}/t.h5", "--start", "0.05", "--end", "0.4"),
    ("convert", "{f}", "{out}/c.mcap"),
    ("recover", "{f}", "-o", "{out}/r.mcap"),
    ("replay", "{f}"),
    ("compare", "{seed}", "{f}"),
)
_TOML_PATHS: tuple[tuple[str, ...], ...] = (
    ("simulate", "--situation", "11", "--stand", "{f}", "-o", "{out}/s.csv"),
    ("model", "modes", "--stand", "{f}"),
    ("run", "--stand", "{f}", "--situation", "11", "-o", "{out}/x.mcap"),
)
_TDMS_PATHS: tuple[tuple[str, ...], ...] = (
    ("import", "{f}", "-o", "{out}/x.h5"),
    ("info", "{f}"),
)


def _first_corpus() -> list[tuple[str, tuple[str, ...]]]:
    cases: list[tuple[str, tuple[str, ...]]] = []
    for path in sorted((FIXTURES / "fuzz").iterdir()):
        if path.suffix in (".h5", ".mcap"):
            paths = READ_PATHS
        elif path.suffix == ".tdms":
            paths = _TDMS_PATHS
        elif path.suffix == ".toml":
            paths = _TOML_PATHS
        else:
            continue
        cases += [(f"fuzz/{path.name}", argv) for argv in paths]
    return cases


def _c(*words: str) -> tuple[str, ...]:
    return words


#: the second corpus: file -> the commands its README names (and the neighbours that
#: share the read path: cat's fault also through trim and info)
_SECOND: dict[str, tuple[tuple[str, ...], ...]] = {
    "f001_memory_cat.mcap": (_c("cat", "{f}", "--events"),),
    "g003_memory_cat.mcap": (_c("cat", "{f}", "--events"),),
    "f002_traceback_cat.mcap": (_c("cat", "{f}"),),
    "g002_traceback_cat.mcap": (_c("cat", "{f}"),),
    "f003_traceback_cat.mcap": (_c("cat", "{f}", "--start", "0.1"),),
    "g001_traceback_cat.mcap": (_c("cat", "{f}", "--start", "0.1"),),
    "g004_traceback_trim.mcap": (
        _c("trim", "{f}", "-o", "{out}/t.csv", "--start", "0.05", "--end", "0.4"),
    ),
    "f004_traceback_cat.mcap": (_c("cat", "{f}", "--events"),),
    "f005_traceback_recover.mcap": (
        _c("recover", "{f}", "-o", "{out}/fixed.mcap"),
        _c("convert", "{f}", "{out}/x.mcap"),
    ),
    "g005_traceback_recover.mcap": (_c("recover", "{f}", "-o", "{out}/fixed.mcap"),),
    "f006_traceback_info.mcap": (_c("info", "{f}"),),
    "g010_traceback_info.mcap": (_c("info", "{f}"),),
    "f007_memory_replay.mcap": (_c("replay", "{f}"),),
    "g006_memory_replay.mcap": (_c("replay", "{f}"),),
    "g009_memory_replay.mcap": (_c("replay", "{f}"),),
    "f012_memory_replay.h5": (_c("replay", "{f}"),),
    "f008_memory_compare.mcap": (_c("compare", "{seed}", "{f}"),),
    "g007_memory_compare.mcap": (_c("compare", "{seed}", "{f}"),),
    "g008_memory_compare.mcap": (_c("compare", "{seed}", "{f}"),),
    "g013_memory_compare.h5": (_c("compare", "{seed}", "{f}"),),
    "f009_traceback_cat.h5": (_c("cat", "{f}", "--events"),),
    "g011_traceback_cat.h5": (_c("cat", "{f}", "--events"),),
    "f013_traceback_cat.h5": (_c("cat", "{f}", "--start", "0.1"),),
    "g012_traceback_cat.h5": (_c("cat", "{f}", "--start", "0.1"),),
    "f010_traceback_trim.h5": (
        _c("trim", "{f}", "-o", "{out}/t.h5", "--start", "0.05", "--end", "0.4"),
    ),
    "f011_traceback_cat.h5": (_c("cat", "{f}", "--end", "0.3"),),
    "g014_traceback_cat.h5": (_c("cat", "{f}", "--end", "0.3"),),
    "f017_traceback_import.csv": (_c("import", "{f}", "--encoding", "hex", "-o", "{out}/x.h5"),),
    "g025_traceback_import.csv": (_c("import", "{f}", "--encoding", "hex", "-o", "{out}/x.h5"),),
    "f021_traceback_import.csv": (_c("import", "{f}", "--encoding", "rot13", "-o", "{out}/x.h5"),),
    "g019_traceback_import.csv": (_c("import", "{f}", "--encoding", "rot13", "-o", "{out}/x.h5"),),
    "f026_traceback_info.csv": (_c("info", "{f}"),),
    "f020_traceback_import.csv": (_c("import", "{f}", "-o", "{out}/x.mcap"),),
    "g028_traceback_import.csv": (_c("import", "{f}", "-o", "{out}/x.mcap"),),
    "f054_hang_import.csv": (_c("import", "{f}", "-o", "{out}/x.h5"),),
    "f064_hang_import.csv": (_c("import", "{f}", "-o", "{out}/x.h5"),),
    "f014_unclean_multiline_import.csv": (_c("import", "{f}", "-o", "{out}/x.h5"),),
    "f023_unclean_multiline_import.csv": (_c("import", "{f}", "-o", "{out}/x.h5"),),
    "f038_unclean_multiline_info.csv": (_c("info", "{f}"),),
    "f024_wrong_rc_cat.csv": (_c("cat", "{f}"),),
    "f092_memory_run.toml": (
        _c("run", "--stand", "{f}", "--situation", "11", "-o", "/nonexistent-dir/x.mcap"),
    ),
    "f093_memory_simulate.toml": (
        _c("simulate", "--situation", "11", "--stand", "{f}", "-o", "{out}/s.csv"),
    ),
    "g055_memory_simulate.toml": (
        _c("simulate", "--situation", "11", "--stand", "{f}", "-o", "{out}/s.csv"),
    ),
    "g054_memory_model.toml": (_c("model", "modes", "--stand", "{f}"),),
    "g053_memory_simulate.toml": (
        _c("simulate", "--situation", "11", "--stand", "{f}", "-o", "{out}/s.csv"),
    ),
    "g056_traceback_simulate.toml": (
        _c("simulate", "--situation", "11", "--stand", "{f}", "-o", "{out}/s.csv"),
    ),
    # Parquet: the CLI's reader entry comes with issue 30; PARQUET_ARGV registers it
    "f071_unclean_multiline_info.parquet": (_c("info", "{f}"),),
    "f074_traceback_info.parquet": (_c("info", "{f}"),),
    "f075_unclean_multiline_info.parquet": (_c("info", "{f}"),),
    "f077_traceback_convert.parquet": (_c("convert", "{f}", "{out}/x.mcap"),),
    "f079_traceback_info.parquet": (_c("info", "{f}"),),
    "f081_traceback_info.parquet": (_c("info", "{f}"),),
}

#: the first corpus's files that the second README says `cat` took wrongly
_CAT_TOO = ("hdf5_hang_2.h5", "mcap_endoffile.mcap")


def cases() -> list[tuple[str, tuple[str, ...]]]:
    """(fixture relative to tests/fixtures, argv template), every one."""
    second = [(f"fuzz2/{name}", argv) for name, argvs in _SECOND.items() for argv in argvs]
    extra = [(f"fuzz/{name}", ("cat", "{f}")) for name in _CAT_TOO]
    return _first_corpus() + second + extra


def second_corpus_files() -> set[str]:
    """The file names the second corpus's table covers."""
    return set(_SECOND)


def argv_for(template: tuple[str, ...], path: Path, out: Path, seed: Path) -> list[str]:
    """The template with its placeholders filled."""
    return [w.format(f=path, out=out, seed=seed) for w in template]


#: A 2 GiB address space (the issue's bound) and a hang guard far above any clean refusal.
ADDRESS_SPACE_BYTES = 2 * 2**30
HANG_GUARD_S = 60.0
#: Runs the CLI with the Parquet reader registered (the CLI's own entry: issue 30).
_WITH_PARQUET = (
    "import sys, recordings.tables; from labstand.cli import main; sys.exit(main(sys.argv[1:]))"
)


@dataclass(frozen=True)
class Outcome:
    """What one command did: exit code, stderr, wall time."""

    returncode: int
    stderr: str
    seconds: float


def _limit_address_space() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE_BYTES, ADDRESS_SPACE_BYTES))


def run_case(path: Path, argv: list[str], cwd: Path) -> Outcome:
    """``labstand ARGV`` in a child under the address-space limit (``HANG_GUARD_S`` at most)."""
    exe = Path(sys.executable).with_name("labstand")
    if path.suffix == ".parquet":
        command = [sys.executable, "-c", _WITH_PARQUET, *argv]
    else:
        command = [str(exe), *argv]
    start = time.monotonic()
    try:
        res = subprocess.run(
            command,
            capture_output=True,
            text=True,
            errors="replace",
            timeout=HANG_GUARD_S,
            cwd=cwd,
            check=False,
            preexec_fn=_limit_address_space,
        )
    except subprocess.TimeoutExpired:
        return Outcome(-1, "hang", time.monotonic() - start)
    return Outcome(res.returncode, res.stderr, time.monotonic() - start)
