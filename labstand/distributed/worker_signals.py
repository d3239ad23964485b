"""Preloaded into every local Dask worker process: Ctrl-C is the parent's to handle.

Ctrl-C at a terminal reaches the whole foreground process group, the workers too; each
would die with a KeyboardInterrupt traceback (and its nanny log an error) while the
parent is already stopping the run in order and closing the cluster (which ends the
workers with SIGTERM). Dask calls ``dask_setup`` in the worker's main thread at start.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker: object) -> None:
    """Ignore SIGINT in this worker process."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
