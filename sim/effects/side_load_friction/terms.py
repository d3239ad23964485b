"""Side-load friction's terms: the guide's friction grows with the weight-side tension.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` appends
it to a model composed with this term and calls its hooks (``sl_<hook>``, signatures in
``sim.physics.kernel_source.HOOKS``). Its one derived constant: ``D_SL`` = μ·sin β, the
share of the weight span's tension that presses the weight sideways onto its guide.
Its imports are for reading and linting only.
"""

from __future__ import annotations

# <imports>
from numba import njit

from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def sl_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """Its derived constant in c."""
    if c[R_SL_ON] > 0.0:
        c[D_SL] = c[R_SL_MU] * c[R_SIN_BETA]
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def sl_zoned(c):  # type: ignore[no-untyped-def]
    """Its friction has the baseline's branches (up, down, the band between)."""
    return c[R_SL_ON] > 0.0


@njit(cache=True, error_model="numpy")
def sl_friction(c, v, zone, t2, fric):  # type: ignore[no-untyped-def]
    """The guide's friction plus μ·sin β·T₂ on the branch held for the step."""
    if c[R_SL_ON] > 0.0:
        side = c[D_SL] * max(t2, 0.0)
        fric += side * zone if zone != 0 else side * v / c[P_VREG]
    return fric


@njit(cache=True, error_model="numpy")
def sl_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp):  # type: ignore[no-untyped-def]
    """Its decay inside the regularisation band, 1/s: μ·sin β·T/(v_reg·m)."""
    if c[R_SL_ON] > 0.0:
        band = c[D_SL] * t_est / (c[P_VREG] * c[P_MASS])
        real, real_exp = max(real, band), max(real_exp, band)
    return osc, osc_exp, real, real_exp
