"""Fixtures of the simulated-stand tests: leak checks, a running stand, socat pairs."""

from __future__ import annotations

import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from sim.config import StandConfig, default_config
from sim.hardware.stand import ScaledClock, SimulatedStand, StandSettings, StandThread
from tests.hardware_sim.leakcheck import no_leaks

__all__ = ["no_leaks"]


@pytest.fixture(scope="session")
def config() -> StandConfig:
    """The paper's stand."""
    return default_config()


def run_stand(config: StandConfig, speed: float = 1.0, **settings: object) -> StandThread:
    """A simulated stand in a background thread (call .start(), then .stop())."""
    stand = SimulatedStand.from_config(
        config, settings=StandSettings(**settings), clock=ScaledClock(speed)
    )
    return StandThread(stand)


@pytest.fixture
def socat_pair(tmp_path: Path) -> Iterator[tuple[str, str]]:
    """Two linked raw ptys made by socat: (server end, client end)."""
    if shutil.which("socat") is None:
        pytest.fail("socat is not installed (make system-tools installs it)")
    a, b = tmp_path / "ptyA", tmp_path / "ptyB"
    proc = subprocess.Popen(
        ["socat", f"pty,raw,echo=0,link={a}", f"pty,raw,echo=0,link={b}"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 5.0
    while not (a.exists() and b.exists()):
        if time.monotonic() > deadline or proc.poll() is not None:
            proc.kill()
            proc.wait()
            pytest.fail("socat did not create its pty pair")
        time.sleep(0.01)
    try:
        yield str(a), str(b)
    finally:
        proc.terminate()
        proc.wait(5)
