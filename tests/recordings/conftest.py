"""Recordings made by the real code paths, in tmp_path."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from labstand.cli import main
from recordings import (
    COMMAND_DTYPE,
    DRIVE_DTYPE,
    GAUGES_DTYPE,
    RecordingMetadata,
    make_metadata,
)
from sim.config import default_config


@pytest.fixture
def meta() -> RecordingMetadata:
    return make_metadata(default_config().to_dict(), "sim", operator_note="test run")


@pytest.fixture
def simulated_mcap(tmp_path: Path) -> Path:
    """``labstand simulate --situation 11 -o sim.mcap``."""
    out = tmp_path / "sim.mcap"
    assert main(["simulate", "--situation", "11", "-o", str(out)]) == 0
    return out


def gauges(n: int, start: int = 0) -> np.ndarray:
    """n gauge samples at 2 kHz from sample ``start``."""
    index = np.arange(start, start + n)
    g = np.zeros(n, GAUGES_DTYPE)
    g["seq"], g["t_ns"] = index, index * 500_000
    g["x_mm"] = 40 * np.sin(index / 2000)
    g["u_mm"] = 0.9 * g["x_mm"]
    g["force_n"] = 45 + np.cos(index / 100)
    g["flags"] = index % 3
    return g


def command(n: int, start: int = 0) -> np.ndarray:
    c = np.zeros(n, COMMAND_DTYPE)
    index = np.arange(start, start + n)
    c["t_ns"], c["x_cmd_mm"] = index * 500_000, 40 * np.sin(index / 2000)
    return c


def drive(n: int, every_ns: int = 20_000_000) -> np.ndarray:
    d = np.zeros(n, DRIVE_DTYPE)
    d["t_ns"] = np.arange(n) * every_ns
    d["position_mm"] = np.linspace(0, 10, n)
    d["speed_mm_s"] = 3.5
    d["status_word"] = 0x0041
    d["trip_code"] = np.arange(n) % 7
    d["enabled"] = np.arange(n) % 2 == 0
    return d
