"""Where the jobs run: an embedded ``LocalCluster`` or an existing Dask scheduler.

The local cluster has one single-threaded worker process per core (``--workers N`` to
choose), and gives each worker's numba kernels ``cores // workers`` threads, so workers
× numba threads never exceeds the machine's cores. A cluster labstand starts is always
closed again, on errors and Ctrl-C too (the nannies terminate their worker processes).
"""

from __future__ import annotations

import argparse
import importlib.util
import logging
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

from labstand.errors import CommandError, ExitCode
from labstand.interrupts import remembered_interrupt

if TYPE_CHECKING:  # dask is imported where it runs: a command's --help stays quick
    from distributed import Client

#: The address of an existing scheduler when ``--scheduler`` is not given (as Dask's own).
SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
#: How long to wait for an existing scheduler before giving up.
CONNECT_TIMEOUT = "15s"


def machine_cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0))


def numba_threads(workers: int, cores: int) -> int:
    """Threads per worker's numba kernels so workers × threads fits the cores."""
    return max(1, cores // max(workers, 1))


#: The thread pools a worker's libraries start, each capped like numba's: the BLAS under
#: numpy and scipy starts one thread per core in every process, so N workers ran N × cores
#: threads (on 16 cores a check's campaigns each took 3.3 times as long).
THREAD_POOLS = ("NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def worker_env(threads: int) -> dict[str, str]:
    """The environment of a local worker: every thread pool capped at ``threads``."""
    return dict.fromkeys(THREAD_POOLS, str(threads))


@dataclass(frozen=True)
class ClusterOptions:
    """``--workers`` and ``--scheduler`` as given."""

    workers: int | None = None
    scheduler: str | None = None
    #: Threads of each local worker's numba kernels (default: cores // workers).
    numba_threads: int | None = None

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> ClusterOptions:
        """From the parsed options (CommandError, exit 2, if they contradict)."""
        workers = getattr(args, "workers", None)
        scheduler = getattr(args, "scheduler", None) or os.environ.get(SCHEDULER_ENV) or None
        if workers is not None and workers < 1:
            raise CommandError(f"--workers must be at least 1, got {workers}", ExitCode.USAGE)
        if workers is not None and scheduler is not None:
            raise CommandError(
                f"--workers sizes the local cluster; the scheduler {scheduler} has its own "
                "workers (drop one of them)",
                ExitCode.USAGE,
            )
        return cls(workers, scheduler)

    @property
    def explicit(self) -> bool:
        """The user asked for a cluster (else a single job may run in this process)."""
        return self.workers is not None or self.scheduler is not None


def add_cluster_options(parser: argparse.ArgumentParser) -> None:
    """--workers N, --scheduler ADDRESS."""
    group = parser.add_argument_group("where the jobs run (Dask)")
    group.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="worker processes of the embedded local cluster (default: one per core)",
    )
    group.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help=f"an existing Dask scheduler, e.g. tcp://host:8786 (default: ${SCHEDULER_ENV}, "
        "else a local cluster)",
    )


def _dashboard_available() -> bool:
    return importlib.util.find_spec("bokeh") is not None


@contextmanager
def open_client(
    options: ClusterOptions, say: Callable[[str], None]
) -> Iterator[tuple[Client, int | None]]:
    """A client on the chosen cluster, and the numba threads each task should set.

    The thread count is None on an existing cluster: its workers were started with their
    own ``NUMBA_NUM_THREADS`` (see docs/scale-out.md).
    """
    from distributed import Client, LocalCluster

    # Dask configures its loggers at INFO on import: its connection chatter, and its
    # warnings while it stops (a busy worker killed after Ctrl-C), would bury the progress
    # and the one closing line; -v (labstand's DEBUG) keeps them.
    verbose = logging.getLogger("labstand").isEnabledFor(logging.DEBUG)
    if not verbose:
        logging.getLogger("distributed").setLevel(logging.ERROR)
    if options.scheduler is not None:
        try:
            client = Client(options.scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as err:
            raise CommandError(
                f"cannot reach the Dask scheduler at {options.scheduler}: {err}"
            ) from None
        with client:
            info = client.scheduler_info(n_workers=-1)
            workers = len(info.get("workers", {}))
            # The scheduler always serves HTTP (health, metrics); the dashboard pages
            # only with bokeh installed there.
            where = f"dashboard {client.dashboard_link} (if the scheduler has bokeh)"
            say(f"scheduler {options.scheduler}, {workers} worker(s) now; {where}")
            yield client, None
        return
    cores = machine_cores()
    n = options.workers or cores
    threads = options.numba_threads or numba_threads(n, cores)
    with (
        remembered_interrupt() as interrupted,
        LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            scheduler_port=0,
            # A free loopback port: the scheduler serves HTTP even without a dashboard
            # (its default, 8787, may be taken by another cluster).
            dashboard_address="127.0.0.1:0",
            # the workers' own log: a busy worker outlives the scheduler after Ctrl-C
            # and says so with a traceback (heartbeat failed); -v keeps their errors
            silence_logs=logging.ERROR if verbose else logging.CRITICAL,
            env=worker_env(threads),
            preload=["labstand.distributed.worker_signals"],  # Ctrl-C: the parent's alone
        ) as cluster,
        Client(cluster) as client,
    ):
        if interrupted.is_set():  # Ctrl-C while the workers started
            interrupted.raise_it()
        say(
            f"local cluster: {n} worker process(es) × 1 thread, numba {threads} thread(s) "
            f"each; {_dashboard(client)}"
        )
        yield client, threads
        if interrupted.is_set():  # a Ctrl-C that Dask's waiting swallowed
            interrupted.raise_it()


def _dashboard(client: Client) -> str:
    if not _dashboard_available():
        return "dashboard off (bokeh is not installed)"
    link = client.dashboard_link
    return f"dashboard {link}" if link else "no dashboard"
