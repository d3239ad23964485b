"""Benchmark: many campaigns on Dask — speed-up of 2 workers over 1, overhead, data per task.

1. Eight blind campaigns of the check (``diagnose-check --small``: four classes × two
   masses, seed 0) through the same code path as the command (``run_cases``), on a local
   cluster of 1 worker with 1 numba thread, 1 worker with 2 numba threads, and 2 workers
   with 1 numba thread each — side by side in one run, on one machine.
2. Scheduler overhead: 1 000 trivial tasks (``client.submit``) on 2 local workers, wall
   time per task.
3. Data shipped per task: the pickled job (function, shared setup, campaign) and its
   pickled result, as Dask sends them (cloudpickle).

Run: ``PYTHONPATH=. .venv/bin/python benchmarks/bench_campaigns.py [--skip-campaigns]``.
"""

from __future__ import annotations

import argparse
import functools
import statistics
import time

import cloudpickle

from labstand.commands.diagnose_check import CheckSetup, check_job, run_cases
from labstand.distributed import ClusterOptions, Progress, open_client
from labstand.distributed.jobs import call_job
from sim.checks.check import SMALL_CAMPAIGN, check_cases
from sim.checks.otherstand.campaign import OTHER_SMALL
from sim.config import default_config

CLASSES = ["none", "fibre_viscoelastic", "dial_gauge_calibration", "stick_slip_friction"]
MASSES = [3.096, 8.131]


def quiet(_message: str) -> None:
    pass


def campaigns(setup: CheckSetup) -> None:
    specs = check_cases(0, 1, CLASSES, MASSES)
    print(f"{len(specs)} campaigns (diagnose-check --small, seed 0):")
    answers: dict[str, list[str]] = {}
    base = None
    for label, workers, threads in (
        ("1 worker,  numba 1 thread ", 1, 1),
        ("1 worker,  numba 2 threads", 1, 2),
        ("2 workers, numba 1 thread ", 2, 1),
    ):
        options = ClusterOptions(workers=workers, numba_threads=threads)
        started = time.perf_counter()
        results = run_cases(setup, specs, options, Progress("bench", len(specs), quiet=True))
        wall = time.perf_counter() - started
        base = base or wall
        per = [r.seconds for r in results]
        answers[label] = [r.value[0].answer if r.value else "FAILED" for r in results]
        print(
            f"  {label}: {wall:6.1f} s wall ({base / wall:4.2f}×), per campaign median "
            f"{statistics.median(per):5.1f} s (min {min(per):.1f}, max {max(per):.1f})"
        )
    same = len({tuple(a) for a in answers.values()}) == 1
    print(f"  answers identical in all three: {same}")


def overhead() -> None:
    with open_client(ClusterOptions(workers=2), quiet) as (client, _):
        client.submit(abs, -1).result()  # warm
        for n in (1000,):
            started = time.perf_counter()
            futures = [client.submit(abs, -i, pure=False) for i in range(n)]
            client.gather(futures)
            wall = time.perf_counter() - started
            print(f"scheduler overhead: {n} trivial tasks on 2 workers in {wall:.2f} s = "
                  f"{wall / n * 1e3:.2f} ms per task")  # fmt: skip


def shipped(setup: CheckSetup) -> None:
    spec = check_cases(0, 1, ["fibre_viscoelastic"], [8.131])[0]
    job = functools.partial(check_job, setup)
    sent = len(cloudpickle.dumps((call_job, job, spec, 1)))
    started = time.perf_counter()
    result = call_job(job, spec, None)
    wall = time.perf_counter() - started
    back = len(cloudpickle.dumps(result))
    print(f"data per check task: {sent / 1e3:.1f} kB sent, {back / 1e3:.1f} kB back "
          f"(campaign diagnosed in {wall:.1f} s here)")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-campaigns", action="store_true", help="overhead and data only")
    args = parser.parse_args()
    setup = CheckSetup(default_config(), SMALL_CAMPAIGN, "same", OTHER_SMALL)
    shipped(setup)
    overhead()
    if not args.skip_campaigns:
        campaigns(setup)


if __name__ == "__main__":
    main()
