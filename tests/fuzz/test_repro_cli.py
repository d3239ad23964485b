"""Every fuzz-found input through every command its README names, as the real command.

Each must end in one line on stderr (no traceback, no library warning before it), exit 2,
under a 2 GiB address space (``RLIMIT_AS`` in the child: a memory blow-up fails there),
within the hang guard. The cases run two at a time in child processes; a failure lists
every case that broke. The table is ``repro_cases.py``; the inputs are copies of
``shared/fuzz-repro`` and ``shared/fuzz-repro-2`` in ``tests/fixtures/fuzz{,2}``.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from . import corpus, repro_cases

#: A one-line error that lists 5 000 column names is still unreadable.
MAX_LINE_CHARS = 1000


def test_every_file_of_the_second_corpus_has_a_case() -> None:
    on_disk = {p.name for p in (repro_cases.FIXTURES / "fuzz2").iterdir() if p.name != "README.md"}
    assert on_disk == repro_cases.second_corpus_files()


def _problem(case: tuple[str, tuple[str, ...]], work: Path, seed: Path, i: int) -> str | None:
    name, template = case
    out = work / f"case{i}"
    out.mkdir()
    path = repro_cases.FIXTURES / name
    argv = repro_cases.argv_for(template, path, out, seed)
    got = repro_cases.run_case(path, argv, out)
    lines = got.stderr.splitlines()
    one = len(lines) == 1 and len(lines[0]) <= MAX_LINE_CHARS
    if got.returncode == 2 and one and lines[0].startswith("labstand: error: "):
        return None
    last = lines[-1][:200] if lines else ""
    return (
        f"{name} {' '.join(template)}: exit {got.returncode}, {len(lines)} line(s), "
        f"{got.seconds:.1f} s: {last}"
    )


@pytest.mark.timeout(1800)
def test_every_input_is_refused_in_one_line_exit_2(tmp_path: Path) -> None:
    (tmp_path / "seeds").mkdir()
    seed = corpus.write_seeds(tmp_path / "seeds")[".mcap"]
    cases = repro_cases.cases()
    assert len(cases) > 100
    with ThreadPoolExecutor(max_workers=2) as pool:
        found = pool.map(lambda ic: _problem(ic[1], tmp_path, seed, ic[0]), enumerate(cases))
        problems = [p for p in found if p is not None]
    assert not problems, f"{len(problems)} of {len(cases)} cases:\n" + "\n".join(problems)


def test_every_cut_inside_the_mcap_header_is_refused_by_cat(tmp_path: Path) -> None:
    """The README's `head -c 9 any.mcap`: `cat` said `[Errno 22] Invalid argument`, exit 1."""
    (tmp_path / "seeds").mkdir()
    data = corpus.write_seeds(tmp_path / "seeds")[".mcap"].read_bytes()
    problems = []
    for size in (1, 8, 9, 12, 20, 40):
        path = tmp_path / f"t{size}.mcap"
        path.write_bytes(data[:size])
        got = repro_cases.run_case(path, ["cat", str(path)], tmp_path)
        lines = got.stderr.splitlines()
        if got.returncode != 2 or len(lines) != 1 or str(path) not in lines[0]:
            problems.append(f"{size} bytes: exit {got.returncode}: {got.stderr[-300:]}")
    assert not problems, problems
