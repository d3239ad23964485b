"""Commands over many recordings: one job each, here (a single one) or on Dask."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from typing import Any

from labstand.distributed.cluster import ClusterOptions, open_client
from labstand.distributed.jobs import JobResult, run_jobs
from labstand.distributed.progress import Progress
from labstand.errors import ExitCode


def run_many(
    args: argparse.Namespace,
    fn: Callable[[Any], Any],
    jobs: Sequence[Any],
    keys: Sequence[str],
    label: str,
) -> tuple[list[Any], int]:
    """``fn`` over ``jobs`` here (one job) or on Dask; the values and the exit code.

    A job that fails is reported on stderr in one line; the exit code is then 2 when every
    failure was bad input, else 1.
    """
    options = ClusterOptions.from_args(args)
    progress = Progress(label, len(jobs), quiet=args.json or len(jobs) == 1)

    def tell(r: JobResult[Any]) -> str:
        return f"{r.key}: {'ok' if r.ok else r.error} ({r.seconds:.1f} s)"

    if len(jobs) <= 1 and not options.explicit:
        results = run_jobs(None, fn, jobs, keys, progress, describe=tell)
    else:
        with open_client(options, progress.say) as (client, threads):
            results = run_jobs(client, fn, jobs, keys, progress, threads, tell)
    failed = [r for r in results if not r.ok]
    for r in failed:
        print(f"labstand: error: {r.error}", file=sys.stderr)
    if not failed:
        return [r.value for r in results], ExitCode.OK
    code = ExitCode.USAGE if all(r.bad_input for r in failed) else ExitCode.FAILURE
    return [r.value for r in results if r.ok], code
