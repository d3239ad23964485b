"""The drive position's low-pass: cut where the motion sinks below the encoder's noise."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import default_config
from sim.identify.traces import drive_cutoff_hz, make_trace

RATE_HZ = 2000.0
QUICK = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=4, ramp_fraction=0.4)
K_N_M, C_N_S_M = 94000.0, 46.9  # the default fibre: what carries x's error into F


def _drive() -> np.ndarray:
    stand = default_config()
    _, x = plan_motion(QUICK, stand.drive).sample(RATE_HZ)
    return x


def _recorded(x: np.ndarray, noise_m: float, seed: int) -> np.ndarray:
    """The encoder's reading: white noise, then 0.1 µm counts."""
    rng = np.random.default_rng(seed)
    return np.round((x + rng.normal(0.0, noise_m, x.size)) / 1e-7) * 1e-7


def _force_error(filtered: np.ndarray, x: np.ndarray) -> float:
    """rms of k·e + c·ė, e the filtered drive's error: what the model's force inherits."""
    e = filtered - x
    return float(np.sqrt(np.mean((K_N_M * e + C_N_S_M * np.gradient(e, 1 / RATE_HZ)) ** 2)))


def _low_passed(x: np.ndarray, cutoff: float) -> np.ndarray:
    if cutoff >= 0.8 * RATE_HZ / 2:
        return x
    return sosfiltfilt(butter(4, cutoff / (RATE_HZ / 2), output="sos"), x, padtype="constant")


def test_the_cutoff_falls_as_the_encoder_noise_rises() -> None:
    x = _drive()
    noises = (0.0, 0.3e-6, 1e-6, 3e-6)
    cutoffs = [drive_cutoff_hz(_recorded(x, noise, 1), RATE_HZ) for noise in noises]
    assert cutoffs == sorted(cutoffs, reverse=True)
    assert cutoffs[0] > 2 * cutoffs[-1]
    assert cutoffs[0] >= 400.0  # counts alone: the corners pass
    assert 60.0 <= cutoffs[2] <= 300.0  # the check's 1 µm: near the old fixed 150 Hz


@pytest.mark.parametrize("noise_m", [0.0, 0.3e-6, 1e-6, 3e-6])
def test_the_chosen_cutoff_loses_little_more_than_the_best_fixed_one(noise_m: float) -> None:
    # The model's force inherits k·e + c·ė from the filtered drive's error e: noise let
    # through, or corners rounded off. The spectra's crossing should lose about as little
    # as the best of a grid of fixed cut-offs, whatever the encoder's noise.
    x = _drive()
    errors = {}
    for seed in (1, 2, 3):
        rec = _recorded(x, noise_m, seed)
        chosen = _low_passed(rec, drive_cutoff_hz(rec, RATE_HZ))
        errors.setdefault("chosen", []).append(_force_error(chosen, x))
        for fixed in (50.0, 100.0, 150.0, 200.0, 300.0, 450.0, 800.0):
            errors.setdefault(fixed, []).append(_force_error(_low_passed(rec, fixed), x))
    mean = {k: float(np.mean(v)) for k, v in errors.items()}
    best = min(v for k, v in mean.items() if k != "chosen")
    assert mean["chosen"] <= 1.3 * best
    if noise_m == 0.0:  # counts alone: the old fixed 150 Hz rounded the corners off
        assert mean[150.0] > 3 * mean["chosen"]


def test_a_trace_filters_its_drive_only_as_far_as_its_noise_asks() -> None:
    x = _drive()
    t = np.arange(x.size) / RATE_HZ
    u, f = np.zeros_like(x), np.full_like(x, 40.0)
    quiet = make_trace("quiet", t, _recorded(x, 0.0, 1), u, f, 8.131)
    noisy = make_trace("noisy", t, _recorded(x, 1e-6, 1), u, f, 8.131)
    assert _force_error(quiet.x_m, x) < _force_error(noisy.x_m, x)
    assert _force_error(noisy.x_m, x) < 0.5 * _force_error(_recorded(x, 1e-6, 1), x)
