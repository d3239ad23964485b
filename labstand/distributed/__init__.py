"""Many independent jobs on Dask: an embedded local cluster or an existing one.

The one way labstand runs many campaigns or recordings at once (``diagnose-check``,
``diagnose --campaigns``, ``table1``, ``replay`` over many recordings):

- ``cluster``: ``open_client`` starts a ``LocalCluster`` sized to the machine (or
  ``--workers N``), or joins a scheduler (``--scheduler`` / ``DASK_SCHEDULER_ADDRESS``),
  and always shuts down what it started, on Ctrl-C too.
- ``jobs``: ``run_jobs`` submits one task per job and gathers them as they finish; a
  job's failure becomes its row's error, a dead worker costs its job a retry.
- ``progress``: the done/total bar with an ETA on stderr.

``sim`` stays free of Dask: the jobs are plain functions of ``sim.identify`` and
``recordings`` that this layer ships to the workers.
"""

from labstand.distributed.cluster import ClusterOptions, add_cluster_options, open_client
from labstand.distributed.jobs import JobResult, run_jobs, say_failures
from labstand.distributed.many import run_many
from labstand.distributed.progress import Progress

__all__ = [
    "ClusterOptions",
    "JobResult",
    "Progress",
    "add_cluster_options",
    "open_client",
    "run_jobs",
    "run_many",
    "say_failures",
]
