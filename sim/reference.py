"""Reference solution of the baseline equations with scipy's solve_ivp.

The same physics as the compiled kernel, written independently and plainly: the
right-hand side evaluates the tension law (max(0, kδ + cδ̇) when δ > 0) directly, and the
integrator's own error control (Radau at tight tolerances, the step never longer than one
sample) resolves the slack/taut switches. Slow; used to check the kernel's accuracy and as
the benchmark's baseline.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from sim.params import StandParams

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ReferenceResult:
    """u and F at the sample times, and the integrator's effort."""

    u_m: FloatArray
    force_n: FloatArray
    rhs_evaluations: int


def tension_n(delta_m: float, delta_rate_m_s: float, params: StandParams) -> float:
    """Fibre tension law of STAND.md §2 (tension only)."""
    if delta_m <= 0.0:
        return 0.0
    return max(0.0, params.stiffness_n_m * delta_m + params.damping_n_s_m * delta_rate_m_s)


def friction_law(params: StandParams) -> Callable[[float], float]:
    """Regularised friction F_f(v) of STAND.md §2, N, as a scalar function."""
    table = params.friction
    if table is None:
        return lambda v: 0.0
    normal = params.normal_force_n * params.friction_scale
    mu = table.pchip()
    lo, hi = table.speed_m_s[0], table.speed_m_s[-1]
    mu_reg = float(mu(table.v_reg_m_s))

    def force(v: float) -> float:
        speed = abs(v)
        if speed < table.v_reg_m_s:
            return normal * mu_reg * v / table.v_reg_m_s
        return math.copysign(normal * float(mu(min(max(speed, lo), hi))), v)

    return force


def solve_reference(
    x_m: FloatArray,
    rate_hz: float,
    params: StandParams,
    method: str = "Radau",
    rtol: float = 1e-9,
    atol: float = 1e-12,
) -> ReferenceResult:
    """Integrate the baseline model with solve_ivp over a piecewise-linear drive input."""
    x = np.asarray(x_m, dtype=np.float64) - float(x_m[0])
    dt = 1.0 / rate_hz
    t_eval = np.arange(x.shape[0]) * dt
    n = params.projection
    m = params.mass_kg
    gravity = params.gravity_along_n
    delta0 = params.preload_m
    last = x.shape[0] - 1
    friction = friction_law(params)

    def drive(t: float) -> tuple[float, float]:
        i = min(int(t / dt), last - 1)
        rate = (x[i + 1] - x[i]) / dt
        return x[i] + rate * (t - i * dt), rate

    def rhs(t: float, y: FloatArray) -> list[float]:
        xt, xd = drive(t)
        delta = delta0 + xt - n * y[0]
        tension = tension_n(delta, xd - n * y[1], params)
        return [y[1], (n * tension - gravity - friction(y[1])) / m]

    sol = solve_ivp(
        rhs,
        (0.0, t_eval[-1]),
        [0.0, 0.0],
        method=method,
        t_eval=t_eval,
        rtol=rtol,
        atol=atol,
        max_step=dt,
    )
    if not sol.success:
        raise RuntimeError(f"reference integration failed: {sol.message}")
    u, v = sol.y
    force = np.empty_like(u)
    for i in range(u.shape[0]):
        xi = x[i]
        xd = (x[i] - x[i - 1]) / dt if i > 0 else 0.0
        force[i] = tension_n(delta0 + xi - n * u[i], xd - n * v[i], params)
    return ReferenceResult(u, force, int(sol.nfev))
