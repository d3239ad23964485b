"""Fixtures of the simulated-stand tests: leak checks, a running stand, socat pairs."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from sim.config import StandConfig, default_config
from sim.hardware.stand import ScaledClock, SimulatedStand, StandSettings, StandThread
from tests.hardware_sim.leakcheck import no_leaks
from tests.ptys import socat_ptys

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
    with socat_ptys(tmp_path) as pair:
        yield pair
