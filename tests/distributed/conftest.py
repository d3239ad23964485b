"""Fixtures of the Dask tests: leak checks, Dask's process-wide helpers, tiny campaigns.

Every test here runs on a real ``LocalCluster`` (worker processes on loopback). The leak
guard fails a test that leaves a thread, a descriptor or a process behind; Dask's
process-wide helpers (its offload thread pool, multiprocessing's resource tracker) live
as long as the interpreter by design, so one throwaway cluster starts them before the
first guarded test.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from pathlib import Path

import pytest
from distributed import Client, LocalCluster

from labstand.cli import main
from tests.hardware_sim.leakcheck import no_leaks

__all__ = ["no_leaks"]

#: Short noisy recordings (2.1 s, three 2 Hz trapezoid cycles): a diagnosis takes seconds.
TINY = [
    "simulate", "--signal", "trapezoidal", "--amplitude-mm", "25", "--frequency-hz", "2",
    "--cycles", "3", "--ramp-fraction", "0.4", "--dwell-start-s", "0.3", "--dwell-end-s", "0.3",
    "--noise",
]  # fmt: skip


@pytest.fixture(scope="session", autouse=True)
def dask_process_helpers() -> Iterator[None]:
    """Start (and close) one cluster so Dask's lifelong helpers exist before any test."""
    with (
        LocalCluster(
            n_workers=1,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            scheduler_port=0,
            dashboard_address="127.0.0.1:0",
            silence_logs=logging.ERROR,
        ) as cluster,  # fmt: skip
        Client(cluster) as client,
    ):
        assert client.submit(abs, -1).result() == 1
    yield


@pytest.fixture(scope="session")
def manifest(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 4-campaign manifest: three tiny campaigns and one whose recording is not one."""
    folder = tmp_path_factory.mktemp("campaigns")
    (folder / "recs").mkdir()
    runs = {
        "plain": ["--seed", "1"],
        "visco": ["--seed", "2", "--effect", "fibre_viscoelastic"],
        "dial": ["--seed", "3", "--effect", "dial_gauge_calibration"],
    }
    for name, extra in runs.items():
        assert main([*TINY, *extra, "-o", str(folder / "recs" / f"{name}.csv")]) == 0
    (folder / "recs" / "broken.csv").write_text("t_s,volts\n0,1\n")
    (folder / "campaigns.toml").write_text(
        "".join(
            f'[campaign.{name}]\nrecordings = ["recs/{name}.csv"]\nmass_kg = 8.131\n'
            f'truth = "{truth}"\n\n'
            for name, truth in (
                ("plain", "none"),
                ("visco", "fibre_viscoelastic"),
                ("broken", "none"),
                ("dial", "dial_gauge_calibration"),
            )
        )
    )
    return folder / "campaigns.toml"
