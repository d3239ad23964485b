"""Shared fixtures: the default stand and helpers to run the CLI in-process."""

from __future__ import annotations

import pytest

from sim.config import StandConfig, default_config


@pytest.fixture(scope="session")
def stand() -> StandConfig:
    """The paper's stand (the embedded default configuration)."""
    return default_config()
