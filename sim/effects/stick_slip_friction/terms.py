"""LuGre friction's terms: a bristle z between the weight and its guide, a Stribeck rise.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` appends
it to a model composed with this term and calls its hooks (``ss_<hook>``, signatures in
``sim.physics.kernel_source``). Its state: the bristle deflection z, ż = v − σ₀|v|z/g(v),
friction σ₀z + σ₁·shape(v)·ż with g(v) = table friction·(1 + r·shape(v)); it replaces
the table's friction (it needs the table). Its relaxation, 1e4/s and more at speed, is
integrated exactly by the exponential step (``integrator._etdrk4``). Derived constants:
``D_SS_ON`` (on, with a table), ``D_SIG0`` = σ₀, ``D_SIG1`` = 2√(σ₀m). Its imports are
for reading and linting only.
"""

from __future__ import annotations

# <imports>
import math

from numba import njit

from sim.physics.fibre import _mu
from sim.physics.kernel import BRISTLE_SWING
from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def _stribeck(v, c):  # type: ignore[no-untyped-def]
    """The Stribeck curve's shape exp(−|v/v_s|^δ): 1 at rest, 0 when sliding fast."""
    r = abs(v) / c[R_SS_VS]
    if c[R_SS_EXP] == 2.0:  # the Gaussian (the default): no power function per step
        return math.exp(-r * r)
    return math.exp(-(r ** c[R_SS_EXP]))


@njit(cache=True, error_model="numpy")
def ss_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """σ₀, σ₁ and the oscillations they add: the bristle's own and what ETD leaves."""
    if c[R_SS_ON] > 0.0 and c[P_FRICTION_N] > 0.0:  # LuGre needs a friction table
        c[D_SS_ON] = 1.0
        c[D_SIG0] = c[R_SS_SIGMA]
        c[D_SIG1] = 2.0 * math.sqrt(c[R_SS_SIGMA] * c[P_MASS])
        own = math.sqrt(c[R_SS_SIGMA] / c[P_MASS])
        osc, osc_exp = max(osc, own), max(osc_exp, own)
        # What an exact relaxation leaves to RK4: the damping σ₁·shape·ż couples the
        # weight to it at σ₁·shape(v)·σ₀|v|/g(v) per metre of bristle, against σ₀; its
        # worst is where |v|·shape(v) peaks, at |v/v_s| = δ^(−1/δ). Measured (σ₀ 1e6 N/m,
        # v_s 3 cm/s): at |λ|·h = 0.5 for it the force is off by 0.06 N, at 0.25 by 0.006 N.
        power = c[R_SS_EXP]
        v_peak = c[R_SS_VS] * power ** (-1.0 / power)
        shape = math.exp(-1.0 / power)
        g_peak = c[P_FRICTION_N] * _mu(v_peak, c) * (1.0 + c[R_SS_RATIO] * shape)
        coupled = c[D_SIG1] * shape * c[R_SS_SIGMA] * v_peak / g_peak - c[R_SS_SIGMA]
        osc_exp = max(osc_exp, 2.0 * math.sqrt(max(coupled, 0.0) / c[P_MASS]))
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def ss_replaces_friction(c):  # type: ignore[no-untyped-def]
    """LuGre replaces the table's friction law (and its branches)."""
    return c[D_SS_ON] > 0.0


@njit(cache=True, error_model="numpy")
def ss_friction_law(c, y, v, replaced, fric, zd):  # type: ignore[no-untyped-def]
    """(replaced, friction N, ż): σ₀z + σ₁·shape·ż."""
    if c[D_SS_ON] > 0.0:
        shape = _stribeck(v, c)
        g = c[P_FRICTION_N] * _mu(abs(v), c) * (1.0 + c[R_SS_RATIO] * shape)
        zd = v - c[D_SIG0] * abs(v) * y[Y_Z] / g
        fric = c[D_SIG0] * y[Y_Z] + c[D_SIG1] * shape * zd
        replaced = True
    return replaced, fric, zd


@njit(cache=True, error_model="numpy")
def ss_rates(c, y, sg, t1, t2, zd):  # type: ignore[no-untyped-def]
    """(ż,) as the friction law computed it."""
    return (zd,)


@njit(cache=True, error_model="numpy")
def ss_decay(c, v, rate):  # type: ignore[no-untyped-def]
    """The bristle's relaxation σ₀|v|/g(v) at the weight's speed v, 1/s (``_etdrk4``)."""
    if c[D_SS_ON] > 0.0:
        g = c[P_FRICTION_N] * _mu(abs(v), c) * (1.0 + c[R_SS_RATIO] * _stribeck(v, c))
        rate = c[D_SIG0] * abs(v) / g
    return rate


@njit(cache=True, error_model="numpy")
def ss_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp):  # type: ignore[no-untyped-def]
    """The bristle's relaxation for RK4; for ETD how fast that rate changes."""
    if c[D_SS_ON] > 0.0:
        speed = abs(y[Y_V]) + 0.05
        g_min = c[P_FRICTION_N] * _mu(speed, c)
        relax = c[D_SIG0] * speed / g_min
        real = max(real, relax + c[D_SIG1] / c[P_MASS])
        # Exact for a frozen rate, but the rate swings through the Stribeck dip at every
        # reversal: still a bound, four times looser (σ₀ 1e6 N/m: 0.04 N off without).
        # Away from reversals the frozen rate errs by the rate's relative change within a
        # step, |a|/|v|·(1 + r·δ/e) at most (|v|/g(v) through the Stribeck dip), |a| at
        # most what the tensions, gravity and friction can give: a tenth per step.
        pull = c[P_PROJ] * t_est + c[P_GRAVITY_N] + g_min * (1.0 + c[R_SS_RATIO])
        a_max = pull / c[P_MASS]
        slowest = abs(y[Y_V]) - a_max * dt
        swing = relax / 4.0
        if slowest > 0.0:
            dip = 1.0 + c[R_SS_RATIO] * c[R_SS_EXP] / math.e
            swing = min(swing, 1.5 * a_max / slowest * dip / BRISTLE_SWING)
        real_exp = max(real_exp, c[D_SIG1] / c[P_MASS], swing)
    return osc, osc_exp, real, real_exp


@njit(cache=True, error_model="numpy")
def ss_start_state(c, x, xd, u, v, force, taut, m):  # type: ignore[no-untyped-def]
    """The bristle holding the measured balance n·F − m·g·sin α, within its sliding value.

    Faster than v_s it is at its sliding value; not observable while sticking, a chained
    run replaces it by the previous segment's.
    """
    z = 0.0
    if c[D_SS_ON] > 0.0:
        g = c[P_FRICTION_N] * _mu(abs(v), c) * (1.0 + c[R_SS_RATIO] * _stribeck(v, c))
        limit = g / c[D_SIG0]
        if abs(v) > c[R_SS_VS]:
            z = limit if v > 0.0 else -limit
        else:
            n = c[P_PROJ]
            z = min(max((n * max(force, 0.0) - c[P_GRAVITY_N]) / c[D_SIG0], -limit), limit)
    return (z,)
