"""Shared helpers of the effect tests: drive series and simple signal measures."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from drivers.signals import SignalSpec, plan_motion
from sim.config import StandConfig
from sim.situations import SITUATIONS

RATE = 2000.0
FloatArray = NDArray[np.float64]


def situation_drive(stand: StandConfig, name: str) -> tuple[FloatArray, float]:
    """Drive samples and weight mass of a paper situation."""
    s = SITUATIONS[name]
    _, x = plan_motion(s.signal, stand.drive).sample(RATE)
    return x, s.mass_kg


def signal_drive(stand: StandConfig, spec: SignalSpec) -> FloatArray:
    """Drive samples of any signal."""
    _, x = plan_motion(spec, stand.drive).sample(RATE)
    return x


def release_drive(
    depth_m: float = 0.005, speed_m_s: float = 0.5, hold_s: float = 1.5
) -> FloatArray:
    """From rest, the drive lets the fibre out by depth_m at speed_m_s and holds: one catch."""
    t = np.arange(int((0.1 + hold_s) * RATE)) / RATE
    return np.clip(-(t - 0.1) * speed_m_s, -depth_m, 0.0)


def best_lag(a: FloatArray, b: FloatArray, max_lag: int = 12) -> int:
    """Lag L (samples) maximising corr(a[n], b[n − L]): a is b delayed by L."""
    core = slice(max_lag, a.shape[0] - max_lag)
    scores = [
        np.corrcoef(a[core], np.roll(b, lag)[core])[0, 1] for lag in range(-max_lag, max_lag + 1)
    ]
    return int(np.argmax(scores)) - max_lag


def slack_ends(force_n: FloatArray) -> NDArray[np.intp]:
    """Indices where the fibre re-tensions (last slack sample)."""
    slack = (force_n <= 0.0).astype(np.int8)
    return np.flatnonzero(np.diff(slack) == -1)
