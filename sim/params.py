"""Physical parameters of the stand for one simulation, SI units (STAND.md §1–§2)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:  # scipy.interpolate loads scipy.optimize (0.3 s): imported where used
    from scipy.interpolate import PchipInterpolator

FloatArray = NDArray[np.float64]

__all__ = ["FrictionTable", "StandParams"]


@dataclass(frozen=True)
class FrictionTable:
    """Weight–guide friction: coefficient μ(v) of the normal force m·g·cos α.

    Attributes
    ----------
    speed_m_s
        Strictly increasing sliding speeds, m/s.
    mu
        Friction coefficient at each speed, dimensionless (≥ 0).
    v_reg_m_s
        Below this speed friction is linear in v (regularisation), m/s.

    Between points μ is a monotone cubic (PCHIP), constant beyond the ends.
    """

    speed_m_s: tuple[float, ...]
    mu: tuple[float, ...]
    v_reg_m_s: float = 0.001

    def pchip(self) -> PchipInterpolator:
        """The interpolant of μ over speed (within the table's range)."""
        from scipy.interpolate import PchipInterpolator

        return PchipInterpolator(np.asarray(self.speed_m_s), np.asarray(self.mu))

    def mu_at(self, speed_m_s: FloatArray) -> FloatArray:
        """μ at non-negative speeds, constant beyond the table's ends."""
        s = np.clip(np.asarray(speed_m_s, dtype=np.float64), self.speed_m_s[0], self.speed_m_s[-1])
        return np.asarray(self.pchip()(s), dtype=np.float64)

    def force_n(self, velocity_m_s: FloatArray, normal_n: float) -> FloatArray:
        """Friction force F_f(v), N, signed with v (it opposes the motion in the ODE)."""
        v = np.asarray(velocity_m_s, dtype=np.float64)
        speed = np.abs(v)
        reg = self.mu_at(np.array([self.v_reg_m_s]))[0] * v / self.v_reg_m_s
        slide = np.sign(v) * self.mu_at(speed)
        return normal_n * np.where(speed >= self.v_reg_m_s, slide, reg)


@dataclass(frozen=True)
class StandParams:
    """Everything the model needs for one run.

    Attributes
    ----------
    mass_kg
        Weight mass m, kg.
    stiffness_n_m
        Fibre stiffness k, N/m.
    damping_n_s_m
        Fibre damping c, N·s/m.
    friction
        Friction table, or None for a frictionless guide.
    friction_scale
        Multiplier on the friction table (a fitted parameter), dimensionless.
    incline_deg
        Incline angle α, degrees.
    lateral_offset_m
        Offset d of the weight from the drive–pulley plane, m.
    free_length_m
        Free span ℓ₂ from pulley to weight, m.
    fibre_length_m
        Whole fibre, m.
    fibre_mass_kg
        Whole fibre, kg.
    pulley_radius_m
        Pulley radius r, m.
    wrap_angle_deg
        Fibre wrap angle φ on the pulley, degrees.
    gravity_m_s2
        Gravitational acceleration g, m/s².
    """

    mass_kg: float
    stiffness_n_m: float
    damping_n_s_m: float
    friction: FrictionTable | None = None
    friction_scale: float = 1.0
    incline_deg: float = 30.6
    lateral_offset_m: float = 0.280
    free_length_m: float = 0.64
    fibre_length_m: float = 1.82
    fibre_mass_kg: float = 4.95e-3
    pulley_radius_m: float = 0.040
    wrap_angle_deg: float = 124.0
    gravity_m_s2: float = 9.81

    @property
    def projection(self) -> float:
        """n = cos β with sin β = d/ℓ₂: how much of the fibre's pull acts along the guide."""
        return math.sqrt(1.0 - (self.lateral_offset_m / self.free_length_m) ** 2)

    @property
    def gravity_along_n(self) -> float:
        """m·g·sin α, N: gravity's pull down the incline."""
        return self.mass_kg * self.gravity_m_s2 * math.sin(math.radians(self.incline_deg))

    @property
    def normal_force_n(self) -> float:
        """m·g·cos α, N: the guide's normal force (the friction's reference)."""
        return self.mass_kg * self.gravity_m_s2 * math.cos(math.radians(self.incline_deg))

    @property
    def preload_tension_n(self) -> float:
        """T₀ = m·g·sin α / n, N: fibre tension at rest."""
        return self.gravity_along_n / self.projection

    @property
    def preload_m(self) -> float:
        """δ₀ = T₀ / k, m: fibre elongation at rest."""
        return self.preload_tension_n / self.stiffness_n_m

    @property
    def drive_span_m(self) -> float:
        """ℓ₁ = L − ℓ₂ − r·φ, m: free fibre between drive and pulley."""
        wrap = self.pulley_radius_m * math.radians(self.wrap_angle_deg)
        return self.fibre_length_m - self.free_length_m - wrap

    @property
    def linear_density_kg_m(self) -> float:
        """Fibre mass per length, kg/m."""
        return self.fibre_mass_kg / self.fibre_length_m

    def with_(self, **changes: float | FrictionTable | None) -> StandParams:
        """A copy with some fields changed."""
        return replace(self, **changes)  # type: ignore[arg-type]
