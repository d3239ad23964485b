"""The pulley's terms: its rim, with inertia and bearing friction, splits the fibre in two.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` appends
it to a model composed with this term and writes or calls its hooks (``pi_<hook>``,
signatures in ``sim.physics.kernel_source``). Its states: the rim's displacement s and
velocity ṡ. With it the fibre is two segments (``D_NSEG`` = 2: drive side up to the rim,
weight side from it), each with its own stiffness, damping and rest elongation by its
length, each taut or slack — the integrator's events are per segment. The rim feels
T₁ − T₂ and the bearing: elasto-plastic presliding (``D_SIGP``, state ``S_PZ``, ``S_PS0``)
limited by the bearing's torque and load friction. Its imports are for reading and
linting only.
"""

from __future__ import annotations

# <imports>
import math

from numba import njit

from sim.physics.fibre import _segments, _set_taut, _tensions
from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def _bearing_limit(c, t1, t2):  # type: ignore[no-untyped-def]
    """Largest bearing presliding displacement at these tensions, m."""
    return (c[D_FB0] + c[D_FBL] * (max(t1, 0.0) + max(t2, 0.0))) / c[D_SIGP]


@njit(cache=True, error_model="numpy")
def pi_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """Two segments (the wrapped arc shared half and half), the rim's mass and bearing."""
    if c[R_PI_ON] > 0.0:
        k, damp, t0 = c[P_STIFF], c[P_DAMP], c[D_T0]
        total, l1, l2 = c[R_FIBRE_LEN], c[R_DRIVE_SPAN], c[R_FREE_SPAN]
        half = 0.5 * (total - l1 - l2)
        f1, f2 = total / (l1 + half), total / (l2 + half)
        c[D_NSEG] = 2.0
        c[D_K1], c[D_C1], c[D_K2], c[D_C2] = k * f1, damp * f1, k * f2, damp * f2
        c[D_D10], c[D_D20] = t0 / (k * f1), t0 / (k * f2)
        c[D_KB1], c[D_KB2] = c[D_KB1] * f1, c[D_KB2] * f2  # a branch's k₂ by its length
        r = c[R_RADIUS]
        c[D_MP] = c[R_PI_J] / (r * r)
        c[D_FB0] = c[R_PI_TORQUE] / r
        c[D_FBL] = c[R_PI_LOAD] * c[R_SIN_HALF_WRAP]
        c[D_SIGP] = (c[D_FB0] + 2.0 * c[D_FBL] * t0) / c[R_PI_PRESLIDE]
        stiff = c[D_K1] + c[D_K2] + c[D_KB1] + c[D_KB2] + c[D_SIGP]
        rim = math.sqrt(stiff / c[D_MP])
        osc, osc_exp = max(osc, rim), max(osc_exp, rim)
        c[E_RIM] = (c[D_C1] + c[D_C2]) / c[D_MP]
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def pi_segments(c, y, xa, xb, xd, n, ext1, rate1, ext2, rate2, q1, q2, d1, f1, d2, f2, dd1, dd2):  # type: ignore[no-untyped-def]
    """Each segment's elongation, its rate and tension law, the rim between them.

    Called (written in place) only while the fibre is two segments (``D_NSEG``).
    """
    d1 = c[D_D10] + xa + xb - y[Y_S] + ext1
    dd1 = xd - y[Y_SD] + rate1
    d2 = c[D_D20] + y[Y_S] - n * y[Y_U] + ext2
    dd2 = y[Y_SD] - n * y[Y_V] + rate2
    f1 = c[D_K1] * d1 + c[D_C1] * dd1 + q1
    f2 = c[D_K2] * d2 + c[D_C2] * dd2 + q2
    return d1, f1, d2, f2, dd1, dd2


@njit(cache=True, error_model="numpy")
def pi_rates(c, y, sg, t1, t2, zd):  # type: ignore[no-untyped-def]
    """(ṡ, s̈): the rim between the segments' tensions and its bearing's presliding force."""
    s_acc = 0.0
    if c[D_NSEG] > 1.5:
        fp = 0.0
        if c[D_SIGP] > 0.0:
            zmax = _bearing_limit(c, t1, t2)
            fp = c[D_SIGP] * min(max(c[S_PZ] + y[Y_S] - c[S_PS0], -zmax), zmax)
        s_acc = (t1 - t2 - fp) / c[D_MP]
    return y[Y_SD], s_acc


@njit(cache=True, error_model="numpy")
def pi_settle(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """The bearing's presliding after an integrated part (elasto-plastic), before others'."""
    if c[D_NSEG] > 1.5 and c[D_SIGP] > 0.0:
        t1, t2 = _tensions(c, _segments(c, y, x, 0.0, xd))
        zmax = _bearing_limit(c, t1, t2)
        c[S_PZ] = min(max(c[S_PZ] + y[Y_S] - c[S_PS0], -zmax), zmax)
        c[S_PS0] = y[Y_S]


@njit(cache=True, error_model="numpy")
def pi_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp):  # type: ignore[no-untyped-def]
    """The rim's damping for RK4 (the exponential step takes it exactly)."""
    real = max(real, c[E_RIM])
    return osc, osc_exp, real, real_exp


@njit(cache=True, error_model="numpy")
def pi_start_state(c, x, xd, u, v, force, taut, m):  # type: ignore[no-untyped-def]
    """The rim where the drive side carries the measured F, moving with the fibre.

    Slack (F below a quarter of the rest tension): where both segments pull alike.
    """
    s, sd = 0.0, 0.0
    if c[D_NSEG] > 1.5:
        n = c[P_PROJ]
        k1, k2 = c[D_K1], c[D_K2]
        sd = (k1 * xd + k2 * n * v) / (k1 + k2)
        if taut:
            s = c[D_D10] + x - (force - c[D_C1] * (xd - sd)) / k1
        else:
            s = (k1 * (c[D_D10] + x) - k2 * (c[D_D20] - n * u)) / (k1 + k2)
    return s, sd


@njit(cache=True, error_model="numpy")
def pi_start(c, y, x, xd, m):  # type: ignore[no-untyped-def]
    """The bearing's presliding holding the tension difference (within its limit)."""
    c[S_PZ], c[S_PS0] = 0.0, y[Y_S]
    if c[D_NSEG] > 1.5 and c[D_SIGP] > 0.0:
        _set_taut(c, y, x, xd)
        t1, t2 = _tensions(c, _segments(c, y, x, 0.0, xd))
        zmax = _bearing_limit(c, t1, t2)
        c[S_PZ] = min(max((t1 - t2) / c[D_SIGP], -zmax), zmax)
