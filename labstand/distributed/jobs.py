"""Run independent jobs on a Dask client and gather them as they finish.

Faults, and what each costs:

- a job that raises (a bad recording): its result carries the error, the others go on;
  it is not retried (it would fail the same way);
- a worker process that dies under a job: the scheduler gives the job to another
  worker (Dask's ``distributed.scheduler.allowed-failures``, 3 by default); only a job
  that kills that many workers is reported as failed;
- Ctrl-C: the pending jobs are cancelled and the caller's ``open_client`` closes the
  cluster.
"""

from __future__ import annotations

import sys
import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from labstand.distributed.progress import Progress
from labstand.errors import ExitCode, describe_os_error
from labstand.interrupts import Interrupt, remembered_interrupt

if TYPE_CHECKING:  # dask is imported where it runs: a command's --help stays quick
    from distributed import Client

T = TypeVar("T")
R = TypeVar("R")


@dataclass(frozen=True)
class JobResult(Generic[R]):
    """How one job ended: its value, or its error in one line."""

    key: str
    value: R | None
    error: str | None
    #: The exception's type name (``RecordingError``, ``KilledWorker``, ...), or None.
    error_type: str | None
    seconds: float
    #: The worker's address, or ``local`` when run in this process.
    worker: str
    #: The job failed on its input (a ValueError: a bad recording, stand file, value).
    bad_input: bool = False

    @property
    def ok(self) -> bool:
        """Finished without an error."""
        return self.error is None


def _where() -> str:
    from distributed import get_worker

    try:
        return str(get_worker().address)
    except ValueError:  # not on a worker
        return "local"


def call_job(
    fn: Callable[[T], R], item: T, threads: int | None
) -> tuple[R | None, str | None, str | None, float, str, bool]:
    """Run ``fn(item)`` on a worker: (value, error, error type, seconds, worker, bad input).

    Every exception of the job becomes its result (not a task failure, which Dask would
    retry or re-raise here); a dying process is Dask's to retry.
    """
    if threads is not None:
        import numba

        # Per calling thread in numba; NUMBA_NUM_THREADS (the worker's env) is the cap.
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))  # type: ignore[attr-defined]
    started = time.perf_counter()
    try:
        value = fn(item)
    except Exception as err:  # the job's failure is data, reported in its row
        seconds = time.perf_counter() - started
        message, bad = str(err) or repr(err), isinstance(err, ValueError)
        if isinstance(err, OSError):  # in words, as the command line says it (labstand.errors)
            message, code = describe_os_error(err)
            bad = code == ExitCode.USAGE
        return None, message, type(err).__name__, seconds, _where(), bad
    return value, None, None, time.perf_counter() - started, _where(), False


def run_jobs(
    client: Client | None,
    fn: Callable[[T], R],
    items: Sequence[T],
    keys: Sequence[str],
    progress: Progress,
    threads: int | None = None,
    describe: Callable[[JobResult[R]], str] | None = None,
) -> list[JobResult[R]]:
    """``fn`` over ``items`` (named by ``keys``), results in the items' order.

    ``client`` None runs them here one after another (the same wrapper, the same
    results). ``describe`` says how a job went on the progress line.
    """
    tell = describe or (lambda r: f"{r.key}: {'ok' if r.ok else r.error}")
    results: dict[int, JobResult[R]] = {}
    if client is None:
        try:
            for i, item in enumerate(items):
                results[i] = JobResult(keys[i], *call_job(fn, item, threads))
                progress.advance(tell(results[i]))
        finally:
            progress.close()
        return [results[i] for i in range(len(items))]
    run_id = uuid.uuid4().hex[:8]
    with remembered_interrupt(raise_now=False) as submitting:  # every future whole
        futures = [
            client.submit(call_job, fn, item, threads, key=f"labstand-{run_id}-{i}", pure=False)
            for i, item in enumerate(items)
        ]
    with remembered_interrupt() as interrupted:
        if submitting.is_set():
            interrupted.terminated = submitting.terminated
            interrupted.set()
        return _gather(client, futures, keys, progress, tell, interrupted)


def _gather(
    client: Client,
    futures: list[Any],
    keys: Sequence[str],
    progress: Progress,
    tell: Callable[[JobResult[R]], str],
    interrupted: Interrupt,
) -> list[JobResult[R]]:
    """The jobs' results as they finish, in the items' order; Ctrl-C cancels the rest."""
    from distributed import as_completed

    index = {f.key: i for i, f in enumerate(futures)}
    results: dict[int, JobResult[R]] = {}
    try:
        if interrupted.is_set():  # during the submission
            interrupted.raise_it()
        for future in as_completed(futures):
            if interrupted.is_set():
                interrupted.raise_it()
            i = index[future.key]
            try:
                out: tuple[Any, str | None, str | None, float, str, bool] = future.result()
                results[i] = JobResult(keys[i], *out)
            except Exception as err:  # KilledWorker, a lost scheduler: that job's error
                results[i] = JobResult(keys[i], None, f"{type(err).__name__}: {err}",
                                       type(err).__name__, 0.0, "")  # fmt: skip
            progress.advance(tell(results[i]))
        if interrupted.is_set():
            interrupted.raise_it()
    finally:
        client.cancel([f for f in futures if not f.done()])
        progress.close()
    return [results[i] for i in range(len(futures))]


def say_failures(label: str, results: Sequence[JobResult[Any]]) -> bool:
    """One line on stderr naming every failed job and its error; whether any failed."""
    failed = [r for r in results if not r.ok]
    if failed:
        print(
            f"{label}: {len(failed)} of {len(results)} campaign(s) failed: "
            + "; ".join(f"{r.key}: {r.error}" for r in failed),
            file=sys.stderr,
        )
    return bool(failed)
