"""The fuzzer in the repository, a short run: both generators, every read path, capped memory.

``benchmarks/fuzz_readers.py`` as a child process (its workers fork, cap their address
space and are killed on a hang): a few hundred cases of ``--strategies all`` (byte
mutations and the structural cases of ``structural.py``), which must all read or be
refused in one line. The long run (≥ 10 000 cases) is a benchmark (docs/benchmarks.md).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from . import structural

ROOT = Path(__file__).parents[2]
CASES = 400


@pytest.mark.timeout(600)
def test_a_short_fuzz_run_has_no_traceback_hang_crash_or_unclean_refusal() -> None:
    res = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "fuzz_readers.py"), "--cases", str(CASES),
         "--seed", "2026", "--workers", "2", "--strategies", "all"],
        capture_output=True, text=True, timeout=540, cwd=ROOT, check=False,
    )  # fmt: skip
    out = res.stdout
    assert res.returncode == 0, out + res.stderr
    assert f"{CASES} cases (all, seed 2026)" in out
    counts = {m[1].strip(): int(m[2]) for m in re.finditer(r"^  (\D+?)\s+(\d+)$", out, re.M)}
    assert counts["read fine"] + counts["clean refusals"] == CASES, out
    assert counts["read fine"] > CASES // 20 and counts["clean refusals"] > CASES // 2, out


def test_structural_cases_are_the_same_on_every_run(tmp_path: Path) -> None:
    seeds = structural.write_seeds(tmp_path)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    kinds = set()
    for i in range(len(structural.KINDS)):
        a = structural.make_case(seeds, 5, i, tmp_path / "a")
        b = structural.make_case(seeds, 5, i, tmp_path / "b")
        assert b.path.read_bytes() == a.path.read_bytes() and a.edits == b.edits
        kinds.add(a.path.suffix)
    assert kinds == set(structural.KINDS)


#: (seed, structural case) that broke once in a long benchmark run: a chunk whose Channel
#: record was edited and re-packed (size and CRC right), so the window reader, which
#: trusts the summary's channels, read a file the whole read refuses. Tied to
#: structural.py as it is: an edit there changes which files these are.
FOUND = [(1, 2157)]


@pytest.mark.parametrize(("seed", "index"), FOUND)
def test_cases_the_long_run_found(seed: int, index: int, tmp_path: Path) -> None:
    case = structural.make_case(structural.write_seeds(tmp_path), seed, index, tmp_path)
    try:
        structural.read(case)
    except structural.EXPECTED as err:
        assert "\n" not in str(err) and str(case.path) in str(err)
