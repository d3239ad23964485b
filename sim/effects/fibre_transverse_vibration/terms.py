"""The string modes' terms: each free span's first transverse mode, driven by gravity.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` appends
it to a model composed with this term and calls its hooks (``tv_<hook>``, signatures in
``sim.physics.kernel_source``). Its states: the amplitudes and rates a₁, ȧ₁ (drive span)
and a₂, ȧ₂ (weight span), ä = F − ω²(T)·a − c·ȧ with ω² = (π/L)²·T/ρ; a span's sag
lengthens its segment's geometric path by ST·(a² − a_rest²). Derived constants per span:
``D_W*`` (ω² per newton), ``D_F*`` (modal load), ``D_AR*`` (rest sag), ``D_AR*SQ``,
``D_ST*``, ``D_CM*`` (modal damping). Its imports are for reading and linting only.
"""

from __future__ import annotations

# <imports>
import math

from numba import njit

from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def tv_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """Constants of the first string mode of each free span (0 drive side, 1 weight side)."""
    if c[R_TV_ON] <= 0.0:
        return osc, osc_exp, real
    t0 = c[D_T0]
    for span in range(2):
        if span == 0:  # the drive span hangs vertically, tilted by drive_span_tilt_deg
            length = c[R_DRIVE_SPAN]
            g_perp = c[R_GRAVITY] * math.sin(math.radians(c[R_TV_TILT]))
        else:
            length = c[R_FREE_SPAN]
            g_perp = c[R_G_PERP_WEIGHT_SPAN]
        w = (math.pi / length) ** 2 / c[R_LIN_DENSITY]  # ω² per newton of tension
        force = 4.0 / math.pi * g_perp * c[R_TV_LOAD]  # modal load per modal mass, m/s²
        rest = force / (w * t0)
        c[D_W1 + span] = w
        c[D_F1 + span] = force
        c[D_AR1 + span] = rest
        c[D_AR1SQ + span] = rest * rest
        c[D_ST1 + span] = math.pi**2 / (4.0 * length)  # geometric stretch = ST·a²
        c[D_CM1 + span] = 2.0 * c[R_TV_ZETA] * math.sqrt(w * t0)
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def tv_rest(c):  # type: ignore[no-untyped-def]
    """At rest the strings hang at their gravity sag."""
    if c[R_TV_ON] > 0.0:
        return c[D_AR1], 0.0, c[D_AR2], 0.0
    return 0.0, 0.0, 0.0, 0.0


@njit(cache=True, error_model="numpy")
def tv_extension(c, y, ext1, rate1, ext2, rate2):  # type: ignore[no-untyped-def]
    """Each span's sag beyond its rest sag takes up fibre length (and its rate)."""
    if c[R_TV_ON] > 0.0:
        a1, a2 = y[Y_A1], y[Y_A2]
        ext1 = c[D_ST1] * (a1 * a1 - c[D_AR1SQ])
        rate1 = 2.0 * c[D_ST1] * a1 * y[Y_AD1]
        ext2 = c[D_ST2] * (a2 * a2 - c[D_AR2SQ])
        rate2 = 2.0 * c[D_ST2] * a2 * y[Y_AD2]
    return ext1, rate1, ext2, rate2


@njit(cache=True, error_model="numpy")
def tv_rates(c, y, sg, t1, t2, zd):  # type: ignore[no-untyped-def]
    """(ȧ₁, ä₁, ȧ₂, ä₂): each mode stiffened by its span's tension."""
    aa1, aa2 = 0.0, 0.0
    if c[R_TV_ON] > 0.0:
        aa1 = c[D_F1] - c[D_W1] * max(t1, 0.0) * y[Y_A1] - c[D_CM1] * y[Y_AD1]
        aa2 = c[D_F2] - c[D_W2] * max(t2, 0.0) * y[Y_A2] - c[D_CM2] * y[Y_AD2]
    return y[Y_AD1], aa1, y[Y_AD2], aa2


@njit(cache=True, error_model="numpy")
def tv_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp):  # type: ignore[no-untyped-def]
    """The modes' frequency at the tension to come, while a mode is excited."""
    strings = abs(y[Y_A1]) + abs(y[Y_AD1]) + abs(y[Y_A2]) + abs(y[Y_AD2]) + abs(c[D_F1] + c[D_F2])
    if c[R_TV_ON] > 0.0 and strings > 0.0:  # an unexcited string mode stays exactly zero
        modes = math.sqrt(max(c[D_W1], c[D_W2]) * t_est) + c[D_CM1] + c[D_CM2]
        osc, osc_exp = max(osc, modes), max(osc_exp, modes)
    return osc, osc_exp, real, real_exp


@njit(cache=True, error_model="numpy")
def tv_start_state(c, x, xd, u, v, force, taut, m):  # type: ignore[no-untyped-def]
    """Static sag for the measured tension (rest sag while slack), still.

    Not observable from the gauges: a chained run replaces it by the previous segment's.
    """
    a1, a2 = 0.0, 0.0
    if c[R_TV_ON] > 0.0:
        scale = c[D_T0] / force if taut else 1.0
        a1, a2 = c[D_AR1] * scale, c[D_AR2] * scale
    return a1, 0.0, a2, 0.0
