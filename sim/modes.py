"""Linearised natural frequencies of the baseline model about static rest (taut fibre).

Linearising m·ü = n·(k·δ + c·δ̇) − m·g·sin α − F_f(u̇) about rest, with δ = δ₀ − n·u and
the drive held, gives one mode: m·ü + n²c·u̇ + n²k·u = 0, so ω² = n²k/m and the damping
ratio is ζ = n²c / (2·m·ω). Friction is left out of ζ on purpose: its slope at rest is the
regularisation's (f(v_reg)/v_reg, thousands of N·s/m), a numerical stand-in for sticking,
not a viscous damping a linear mode could carry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sim.params import StandParams

__all__ = ["Mode", "linear_modes"]


@dataclass(frozen=True)
class Mode:
    """One linearised mode."""

    name: str
    frequency_hz: float  # undamped natural frequency
    damping_ratio: float
    damped_frequency_hz: float


def linear_modes(params: StandParams) -> list[Mode]:
    """The baseline model's linearised modes (one: the weight on the fibre's spring)."""
    n = params.projection
    omega = math.sqrt(n * n * params.stiffness_n_m / params.mass_kg)
    damping = n * n * params.damping_n_s_m
    zeta = damping / (2 * params.mass_kg * omega)
    damped = omega * math.sqrt(max(0.0, 1 - zeta * zeta))
    return [Mode("weight on fibre", omega / (2 * math.pi), zeta, damped / (2 * math.pi))]
