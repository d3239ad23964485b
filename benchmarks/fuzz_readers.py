"""Thousands of mutated files through every reader: how many read, are refused, or break.

The cases are seeded (the same files on every run), from two generators:
``tests/fuzz/corpus.py`` (``--strategies mutations``: valid MCAP, HDF5, CSV, TDMS and
stand TOML files, each with one to three byte edits) and ``tests/fuzz/structural.py``
(``structural``: cuts at MCAP records and HDF5 object headers, framing-consistent edits,
checksum-valid files with wrong types, links, shapes and times, CSV/Parquet/TOML
extremes, read through every read path: whole, salvaging, window, grid, rewrite);
``all`` alternates them. Each case runs in a worker process (forked, so no start-up cost
per case) with its address space capped at what it holds plus ``--memory-gib``: an
allocation beyond it is a MemoryError, counted as a traceback. A case that does not
answer within ``--timeout-s`` is a hang (the worker is killed and replaced), a worker
that dies is a crash. Run from the repository's root::

    .venv/bin/python benchmarks/fuzz_readers.py [--cases 10000] [--seed 1] [--workers 2]
        [--strategies all]

Prints the counts: read fine, clean refusals (the package's error, one line naming the
file), unclean refusals (the right type, but several lines or no file name),
tracebacks (any other exception, the first few listed), hangs and crashes.
"""

from __future__ import annotations

import argparse
import logging
import multiprocessing
import resource
import shutil
import sys
import tempfile
import time
import warnings
from collections import Counter
from collections.abc import Callable
from multiprocessing.connection import Connection, wait
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the corpus lives in tests/

from recordings import RecordingError
from sim.config import ConfigError
from tests.fuzz import corpus, structural

OUTCOMES = ("read", "refused", "unclean", "traceback", "hang", "crash")


def _cap_memory(extra_bytes: int) -> None:
    """Cap the worker's address space at what it has now plus ``extra_bytes``."""
    status = Path("/proc/self/status").read_text()
    vm_kib = next(int(line.split()[1]) for line in status.splitlines() if line.startswith("VmSize"))
    limit = vm_kib * 1024 + extra_bytes
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


STRATEGIES = ("mutations", "structural", "all")


def describe(seeds: dict[str, bytes], seed: int, index: int, work: Path, strategy: str) -> object:
    """Write case ``index`` into ``work``; the case (its ``str`` says what was done)."""
    if strategy == "mutations" or (strategy == "all" and index % 2 == 0):
        return corpus.make_case(seeds, seed, index // (2 if strategy == "all" else 1), work)
    return structural.make_case(seeds, seed, index // (2 if strategy == "all" else 1), work)


def _judge(case: object) -> tuple[str, str]:
    """(outcome, detail) of reading one case."""
    if isinstance(case, structural.Case):
        read, expected, path = (lambda: structural.read(case)), structural.EXPECTED, case.path
    else:
        assert isinstance(case, corpus.Case)
        path = case.path
        read, expected = (lambda: corpus.read(path)), (corpus.expected_error(path),)
    try:
        read()
        return "read", ""
    except expected as err:
        message = str(err)
        # a file's fault names the file; an option's (--encoding) or the grid's need not
        named = str(path) in message or message.startswith("--")
        named = named or not isinstance(err, RecordingError | ConfigError)
        clean = "\n" not in message and named
        return ("refused" if clean else "unclean"), message
    except BaseException as err:  # MemoryError and RecursionError included
        return "traceback", f"{type(err).__name__}: {err}"


def _serve(
    conn: Connection, seeds: dict[str, bytes], seed: int, work: Path, memory: int, strategy: str
) -> None:
    """Worker: read case indexes, answer (index, outcome, detail)."""
    _cap_memory(memory)
    warnings.simplefilter("error")  # as pytest runs the readers: a warning is a failure
    logging.disable(logging.CRITICAL)  # the readers log salvaged files' repairs
    while (index := conn.recv()) is not None:
        try:
            case = describe(seeds, seed, index, work, strategy)
        except Exception as err:  # the generator's own failure: not the readers'
            conn.send((index, "traceback", f"generating: {type(err).__name__}: {err}"[:300]))
            continue
        outcome, detail = _judge(case)
        conn.send((index, outcome, detail[:300]))


class _Worker:
    """One worker process and the case it is on."""

    def __init__(self, ctx: multiprocessing.context.ForkContext, args: tuple[object, ...]) -> None:
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=_serve, args=(child, *args), daemon=True)
        self.process.start()
        child.close()
        self.case: int | None = None
        self.since = 0.0

    def give(self, index: int | None) -> None:
        self.case, self.since = index, time.monotonic()
        if index is not None:
            self.conn.send(index)

    def kill(self) -> None:
        self.process.kill()
        self.process.join()
        self.conn.close()


def run(
    cases: int,
    seed: int,
    workers: int,
    timeout_s: float,
    memory_gib: float,
    strategy: str = "all",
) -> int:
    """Run the cases; print the counts; return 1 if any case broke."""
    top = Path(tempfile.mkdtemp(prefix="fuzz-readers-"))
    try:
        return _run(top, cases, seed, workers, timeout_s, memory_gib, strategy)
    finally:
        shutil.rmtree(top, ignore_errors=True)


def _run(
    top: Path,
    cases: int,
    seed: int,
    workers: int,
    timeout_s: float,
    memory_gib: float,
    strategy: str,
) -> int:
    seeds = structural.write_seeds(top)  # the corpus's seeds and a Parquet one
    ctx = multiprocessing.get_context("fork")
    generation = 0

    def start() -> _Worker:
        nonlocal generation
        generation += 1
        work = top / f"w{generation}"
        work.mkdir()
        return _Worker(ctx, (seeds, seed, work, int(memory_gib * 2**30), strategy))

    counts: Counter[str] = Counter()
    listed: dict[str, list[str]] = {k: [] for k in OUTCOMES}
    todo = iter(range(cases))
    pool = [start() for _ in range(workers)]
    for worker in pool:
        worker.give(next(todo, None))
    t0 = time.perf_counter()

    def record(index: int, outcome: str, detail: str) -> None:
        counts[outcome] += 1
        if outcome not in ("read", "refused") and len(listed[outcome]) < 5:
            spare = top / "described"
            spare.mkdir(exist_ok=True)
            described = describe(seeds, seed, index, spare, strategy)  # the parent's own copy
            listed[outcome].append(f"case {index}, {described}: {detail}")

    while any(w.case is not None for w in pool):
        busy = [w for w in pool if w.case is not None]
        for conn in wait([w.conn for w in busy], timeout=0.2):
            worker = next(w for w in busy if w.conn is conn)
            try:
                index, outcome, detail = worker.conn.recv()
            except (EOFError, ConnectionError):  # the worker died: a crash in a C library
                assert worker.case is not None
                record(worker.case, "crash", f"exit code {worker.process.exitcode}")
                pool[pool.index(worker)] = worker = _replace(worker, start)
            else:
                record(index, outcome, detail)
            worker.give(next(todo, None))
        now = time.monotonic()
        for i, worker in enumerate(pool):
            if worker.case is not None and now - worker.since > timeout_s:
                record(worker.case, "hang", f"no answer in {timeout_s:g} s")
                pool[i] = _replace(worker, start)
                pool[i].give(next(todo, None))
    for worker in pool:
        worker.conn.send(None)
        worker.process.join()
    elapsed = time.perf_counter() - t0
    _report(cases, seed, counts, listed, elapsed, strategy)
    return 1 if any(counts[k] for k in ("unclean", "traceback", "hang", "crash")) else 0


def _replace(worker: _Worker, start: Callable[[], _Worker]) -> _Worker:
    worker.kill()
    return start()


def _report(
    cases: int,
    seed: int,
    counts: Counter[str],
    listed: dict[str, list[str]],
    elapsed: float,
    strategy: str,
) -> None:
    print(
        f"{cases} cases ({strategy}, seed {seed}) in {elapsed:.1f} s "
        f"({cases / elapsed:.0f} cases/s)"
    )
    labels = {
        "read": "read fine",
        "refused": "clean refusals",
        "unclean": "refusals not one line naming the file",
        "traceback": "tracebacks (other exception types)",
        "hang": "hangs",
        "crash": "crashes (worker died)",
    }
    for key in OUTCOMES:
        print(f"  {labels[key]:<40} {counts[key]:>6}")
        for line in listed[key]:
            print(f"      {line}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", type=int, default=10_000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout-s", type=float, default=20.0, help="per case")
    parser.add_argument("--memory-gib", type=float, default=2.0, help="per worker, extra")
    parser.add_argument("--strategies", choices=STRATEGIES, default="all")
    args = parser.parse_args()
    return run(
        args.cases, args.seed, args.workers, args.timeout_s, args.memory_gib, args.strategies
    )


if __name__ == "__main__":
    sys.exit(main())
