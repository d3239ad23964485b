"""What a model run returns: series at the input's sample times, SI units."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = ["BatchResult", "ModelRun", "SimResult"]


@dataclass(frozen=True)
class SimResult:
    """One simulated run at the input's sample times (u and F as the gauges record them)."""

    t_s: FloatArray
    x_m: FloatArray
    u_m: FloatArray
    v_m_s: FloatArray
    force_n: FloatArray
    preload_tension_n: float

    @property
    def dynamic_force_n(self) -> FloatArray:
        """F − T₀, the force the paper plots."""
        return self.force_n - self.preload_tension_n

    @property
    def slack(self) -> NDArray[np.bool_]:
        """Samples at which the fibre carries no tension."""
        return self.force_n <= 0.0


@dataclass(frozen=True)
class ModelRun(SimResult):
    """A SimResult (u_m and force_n as *recorded*) with the true channels beside it.

    Attributes
    ----------
    true_u_m
        Weight displacement before the dial gauge and skew, m.
    true_force_n
        Drive-side fibre tension before the force gauge and skew, N.
    weight_force_n
        Weight-side tension (differs from the drive side with the pulley's DOF), N.
    max_substeps
        Largest number of RK4 substeps one sample interval needed.
    """

    true_u_m: FloatArray
    true_force_n: FloatArray
    weight_force_n: FloatArray
    max_substeps: int


@dataclass(frozen=True)
class BatchResult:
    """Many parameter sets on one time base: recorded (and true) channels, (sets, samples)."""

    t_s: FloatArray
    u_m: FloatArray
    v_m_s: FloatArray
    force_n: FloatArray
    true_u_m: FloatArray
    true_force_n: FloatArray
