"""The Maxwell branch's history from the measured elongation, compiled (numba).

Kept apart from the effect's declaration (``sim.effects.fibre_viscoelastic``) so that
reading the registry loads no numba; ``branch_elongation`` imports it when a run needs it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@njit(cache=True)
def branch_part(y: float, share: float, tau_h: float, change: float) -> float:
    """y after ``share`` of a step taut, δ changing linearly by ``change`` over it (exact)."""
    if share <= 0.0:
        return y
    decay = math.exp(-share / tau_h)
    return y * decay + (1.0 - decay) * tau_h * change / share


@njit(cache=True)
def branch_history(
    delta: FloatArray,
    drive_rate: FloatArray,
    weight_rate: FloatArray,
    tau_h: float,
    k: float,
    c: float,
    k2: float,
) -> FloatArray:
    """q/k₂ at every sample from rest; ``tau_h`` is τ in samples.

    ``drive_rate[i]``: the drive's rate over the step that ends at sample i;
    ``weight_rate``: n·v at every sample. One regime switch per step at most, located by
    linear interpolation of δ and of the law.
    """
    out = np.zeros(delta.size)
    decay = math.exp(-1.0 / tau_h)  # over one whole step
    y = 0.0
    for i in range(1, delta.size):
        d0, d1 = delta[i - 1], delta[i]
        change = d1 - d0
        law0 = k * d0 + c * (drive_rate[i] - weight_rate[i - 1]) + k2 * y
        rate1 = c * (drive_rate[i] - weight_rate[i])
        if d0 > 0.0 and law0 > 0.0:  # taut at the step's start
            taut_y = y * decay + (1.0 - decay) * tau_h * change
            law1 = k * d1 + rate1 + k2 * taut_y
            if d1 > 0.0 and law1 > 0.0:
                y = taut_y
            else:  # goes slack where δ or the law reaches zero first
                share = 1.0
                if d1 <= 0.0:
                    share = min(share, d0 / (d0 - d1))
                if law1 <= 0.0:
                    share = min(share, law0 / (law0 - law1))
                y = branch_part(y, share, tau_h, change * share) * math.exp(-(1.0 - share) / tau_h)
        else:
            slack_y = y * decay
            law1 = k * d1 + rate1 + k2 * slack_y
            if d1 > 0.0 and law1 > 0.0:
                # Taut again from where δ turns positive, or (δ already positive) the law:
                # the model locates the one its start shows (``integrator._step``).
                share = d0 / (d0 - d1) if d0 <= 0.0 else max(0.0, law0 / (law0 - law1))
                y = branch_part(y * math.exp(-share / tau_h), 1.0 - share, tau_h,
                                change * (1.0 - share))  # fmt: skip
            else:
                y = slack_y
        out[i] = y
    return out
