"""Mutated files of every reader: each one reads, or is refused with the package's error.

A few hundred cases of the seeded mutator in ``corpus.py`` (the same cases on every run);
``benchmarks/fuzz_readers.py`` runs thousands in child processes and counts hangs. Here
every case runs in-process: a hang ends the test at its timeout, and pytest's warnings
filter turns a warning (an overflow in numpy, an unclosed file) into a failure as well.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from . import corpus

SEED = 2026
CASES = 400
#: Far above any case's time (tens of ms): only a near-hang trips it, not a busy machine.
CASE_LIMIT_S = 20.0


@pytest.fixture(scope="module")
def seeds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    paths = corpus.write_seeds(tmp_path_factory.mktemp("seeds"))
    return {kind: path.read_bytes() for kind, path in paths.items()}


@pytest.mark.parametrize("kind", corpus.KINDS)
def test_the_seed_files_read(kind: str, tmp_path: Path, seeds: dict[str, bytes]) -> None:
    path = tmp_path / f"seed{kind}"
    path.write_bytes(seeds[kind])
    corpus.read(path)


def test_mutations_are_the_same_on_every_run(tmp_path: Path, seeds: dict[str, bytes]) -> None:
    first = [corpus.make_case(seeds, SEED, i, tmp_path).path.read_bytes() for i in range(10)]
    again = [corpus.make_case(seeds, SEED, i, tmp_path).path.read_bytes() for i in range(10)]
    assert first == again
    assert all(data not in seeds.values() for data in first)


#: (seed, case) that broke once in benchmarks/fuzz_readers.py runs: MCAP length fields near
#: 2**64 (OverflowError), NI scaling and sums that overflow (numpy warnings). Tied to the
#: corpus as it is: an edit to corpus.py changes which files these are.
FOUND = [(3, 4080), (3, 7735), (3, 12858), (3, 16918)]


@pytest.mark.parametrize(("seed", "index"), FOUND)
def test_cases_the_benchmark_found(
    seed: int, index: int, tmp_path: Path, seeds: dict[str, bytes]
) -> None:
    case = corpus.make_case(seeds, seed, index, tmp_path)
    try:
        corpus.read(case.path)
    except corpus.expected_error(case.path) as err:
        assert "\n" not in str(err) and str(case.path) in str(err)


@pytest.mark.timeout(900, method="thread")  # a hang inside a C library ignores signals
def test_every_mutated_file_reads_or_is_refused_in_one_line(
    tmp_path: Path, seeds: dict[str, bytes]
) -> None:
    outcomes = {"read": 0, "refused": 0}
    failures: list[str] = []
    for index in range(CASES):
        case = corpus.make_case(seeds, SEED, index, tmp_path)
        start = time.perf_counter()
        try:
            corpus.read(case.path)
            outcomes["read"] += 1
        except corpus.expected_error(case.path) as err:
            outcomes["refused"] += 1
            message = str(err)
            if "\n" in message or str(case.path) not in message:
                failures.append(f"{case}: refusal not one line naming the file: {message!r}")
        except Exception as err:
            failures.append(f"{case}: {type(err).__name__}: {err}")
        elapsed = time.perf_counter() - start
        if elapsed > CASE_LIMIT_S:
            failures.append(f"{case}: took {elapsed:.1f} s")
    assert failures == []
    # The mutator is neither too gentle nor too rough: both outcomes are common.
    assert outcomes["read"] > CASES // 20 and outcomes["refused"] > CASES // 2, outcomes
