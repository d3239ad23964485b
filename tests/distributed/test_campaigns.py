"""Many campaigns on a real Dask LocalCluster: same answers anywhere, faults cost little."""

from __future__ import annotations

import functools
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest

from labstand.campaigns import Campaign, diagnose_campaign, load_manifest
from labstand.cli import main
from labstand.distributed import ClusterOptions, Progress, open_client, run_jobs
from labstand.distributed.cluster import THREAD_POOLS
from sim.effects import EFFECTS
from tests.hardware_sim.leakcheck import gone
from tests.ptys import sigint_not_ignored


def diagnose_json(
    manifest: Path, workers: int, capsys: pytest.CaptureFixture[str], results: Path | None = None
) -> dict[str, dict[str, object]]:
    extra = [] if results is None else ["--results", str(results)]
    code = main(["diagnose", "--campaigns", str(manifest), "--workers", str(workers), "--json",
                 *extra])  # fmt: skip
    captured = capsys.readouterr()
    assert code == 1  # one campaign of the manifest cannot be read
    assert "1 of 4 campaign(s) failed: broken:" in captured.err
    return {r["name"]: r for r in json.loads(captured.out)}


def test_a_manifest_gives_the_same_answers_on_two_workers_as_on_one(
    manifest: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    two = diagnose_json(manifest, 2, capsys, results=tmp_path / "results")
    assert list(two) == ["plain", "visco", "broken", "dial"]  # the manifest's order
    # The bad campaign is reported with its error; the others were diagnosed.
    assert two["broken"]["effect"] is None
    assert "broken.csv" in str(two["broken"]["error"])
    for name in ("plain", "visco", "dial"):
        assert two[name]["effect"] in {"none", *EFFECTS}
        assert str(two[name]["worker"]).startswith("tcp://127.0.0.1:")
    one = diagnose_json(manifest, 1, capsys)
    for name in ("plain", "visco", "dial"):
        for key in ("effect", "effects", "gap_after", "heldout_error_after", "baseline_fit"):
            assert one[name][key] == two[name][key], (name, key)
    # The results as data: a row per campaign, and the confusion matrix.
    table = pd.read_parquet(tmp_path / "results" / "campaigns.parquet")
    assert list(table["name"]) == ["plain", "visco", "broken", "dial"]
    assert table.loc[2, "error"] and pd.isna(table.loc[2, "answer"])
    assert (table.loc[[0, 1, 3], "seconds"] > 0).all()
    answers = [two[n]["effect"] for n in ("plain", "visco", "dial")]
    assert list(table["answer"].iloc[[0, 1, 3]]) == answers
    confusion = pd.read_csv(tmp_path / "results" / "confusion.csv", index_col="truth")
    assert confusion.to_numpy().sum() == 3  # the failed campaign has no answer
    assert confusion.loc["none", two["plain"]["effect"]] >= 1


def test_the_check_runs_its_campaigns_on_two_workers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The campaigns of tests/identify's serial check (seed 11): there both are right.
    args = ["diagnose-check", "--small", "--seed", "11", "--mass-kg", "8.131", "--effects",
            "none", "dial_gauge_calibration", "--workers", "2", "--json",
            "--results", str(tmp_path / "results")]  # fmt: skip
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["cases"] == 2 and out["accuracy"] == 1.0
    table = pd.read_parquet(tmp_path / "results" / "campaigns.parquet")
    assert list(table["name"]) == ["none@8.131kg#0", "dial_gauge_calibration@8.131kg#0"]
    assert list(table["answer"]) == ["none", "dial_gauge_calibration"]
    assert table["worker"].str.startswith("tcp://127.0.0.1:").all()


def _dies_on_first_try(marker: Path, campaign: Campaign) -> dict[str, object]:
    """A campaign whose first attempt kills its worker process (a crash, the OOM killer)."""
    if not marker.exists():
        marker.write_text(str(os.getpid()))
        os._exit(1)
    return {**diagnose_campaign(campaign), "pid": os.getpid()}


def test_a_dead_worker_costs_its_campaign_a_retry_and_a_bad_one_fails_alone(
    manifest: Path, tmp_path: Path
) -> None:
    marker = tmp_path / "died"
    plain, _, broken, _ = load_manifest(manifest)
    progress = Progress("test", 3, quiet=True)
    with open_client(ClusterOptions(workers=2), lambda _m: None) as (client, threads):
        assert threads == 1 or os.cpu_count() == 1
        # Each worker's BLAS and OpenMP pools are capped as its numba threads: uncapped,
        # every worker process starts one thread per core.
        pools = client.run(lambda: {k: os.environ.get(k) for k in THREAD_POOLS})
        assert len(pools) == 2
        assert all(env == dict.fromkeys(THREAD_POOLS, str(threads)) for env in pools.values())
        results = run_jobs(
            client,
            lambda job: job[0](job[1]),
            [(functools.partial(_dies_on_first_try, marker), plain),
             (diagnose_campaign, broken), (str, "fine")],
            ["plain", "broken", "fine"],
            progress,
            threads,
        )  # fmt: skip
        # Let the nanny finish restarting the killed worker before the cluster closes.
        client.wait_for_workers(2, timeout=60)
    assert marker.exists()  # the first attempt ran, and its process died
    dies, fails, fine = results
    assert dies.ok, dies.error
    assert dies.value is not None and dies.value["name"] == "plain"
    assert dies.value["pid"] != int(marker.read_text())  # a second process finished it
    assert dies.value["effect"] in {"none", *EFFECTS}
    assert not fails.ok and fails.bad_input and "broken.csv" in str(fails.error)
    assert fine.value == "fine"
    assert progress.done == 3


def test_ctrl_c_shuts_the_cluster_down_and_leaves_no_process(manifest: Path) -> None:
    # As at a terminal: Ctrl-C sends SIGINT to the whole foreground process group, the
    # command and its worker processes alike.
    with sigint_not_ignored():
        process = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "labstand",
                "diagnose",
                "--campaigns",
                str(manifest),
                "--workers",
                "2",
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
    try:
        assert process.stderr is not None
        line = process.stderr.readline()  # printed once the cluster is up
        assert "local cluster: 2 worker process(es)" in line, line
        family = psutil.Process(process.pid).children(recursive=True)
        spawned = [p for p in family if "spawn_main" in " ".join(p.cmdline())]
        assert len(spawned) >= 2, family  # the two workers
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.communicate()
    assert process.returncode == 130, err
    assert err.strip().splitlines()[-1] == "labstand: interrupted", err
    deadline = time.monotonic() + 10
    while not all(gone(p.pid) for p in family):
        assert time.monotonic() < deadline, [p.pid for p in family if not gone(p.pid)]
        time.sleep(0.05)


def test_table1_and_replay_over_many_recordings(
    manifest: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recs = manifest.parent / "recs"
    good = [recs / f"{name}.csv" for name in ("plain", "visco", "dial")]
    assert main(["table1", *map(str, good), str(recs / "broken.csv"), "--workers", "2",
                 "--json"]) == 2  # fmt: skip
    captured = capsys.readouterr()
    rows = json.loads(captured.out)
    assert [r["recording"] for r in rows] == [str(p) for p in good]  # the rest, in order
    assert captured.err.count("labstand: error: ") == 1 and "broken.csv" in captured.err
    assert main(["replay", *map(str, good), "--workers", "2", "--json"]) == 0
    many = json.loads(capsys.readouterr().out)
    assert main(["replay", str(good[1]), "--json"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert many[1] == one  # the same replay, here or on a worker


def test_an_existing_scheduler_runs_the_same_jobs(
    manifest: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # As docs/scale-out.md says to start them, on loopback: `dask scheduler`, `dask worker`.
    dask = str(Path(sys.executable).parent / "dask")
    info = tmp_path / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    command = [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--dashboard-address",
               "127.0.0.1:0",
               "--scheduler-file", str(info)]  # fmt: skip
    scheduler = subprocess.Popen(command, **quiet)
    worker = None
    try:
        deadline = time.monotonic() + 60
        while not info.exists() or not info.read_text():
            assert time.monotonic() < deadline and scheduler.poll() is None, "no scheduler"
            time.sleep(0.1)
        address = json.loads(info.read_text())["address"]
        worker = subprocess.Popen(
            [dask, "worker", address, "--nworkers", "1", "--nthreads", "1",
             "--host", "127.0.0.1"],
            env={**os.environ, "NUMBA_NUM_THREADS": "1"},
            **quiet,
        )  # fmt: skip
        recs = [manifest.parent / "recs" / f"{n}.csv" for n in ("plain", "visco")]
        both = ["--scheduler", address, "--workers", "1"]
        assert main(["table1", *map(str, recs), "--json", *both]) == 2  # refused
        assert "--workers sizes the local cluster" in capsys.readouterr().err
        os.environ["DASK_SCHEDULER_ADDRESS"] = address
        try:
            assert main(["table1", *map(str, recs)]) == 0
        finally:
            del os.environ["DASK_SCHEDULER_ADDRESS"]
        captured = capsys.readouterr()
        assert f"table1: scheduler {address}, " in captured.err
        assert "table1: [2/2] " in captured.err  # progress, one line per recording
        assert "| plain.csv |" in captured.out and "| visco.csv |" in captured.out
        assert main(["table1", *map(str, recs), "--json", "--scheduler", address]) == 0
        there = json.loads(capsys.readouterr().out)
        assert main(["table1", *map(str, recs), "--json", "--workers", "2"]) == 0
        assert json.loads(capsys.readouterr().out) == there
    finally:
        for process in (worker, scheduler):
            if process is not None:
                process.terminate()
                process.wait(timeout=60)
