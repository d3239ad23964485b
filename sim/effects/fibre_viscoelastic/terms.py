"""The Maxwell branch's terms: a spring k₂ and a damper k₂τ in series, beside the fibre's.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` appends
it to a model composed with this term and calls its hooks (``ve_<hook>``, signatures in
``sim.physics.kernel_source``). Its states: the branch forces q₁, q₂ of the drive-side
and weight-side segments (one segment: q₂ stays 0), q̇ = k₂·δ̇ − q/τ while taut and
q̇ = −q/τ while slack. Derived constants: ``D_KB1``, ``D_KB2`` (k₂ per segment: the
pulley's segments share it by length) and ``D_RELAX`` = 1/τ. Its imports are for
reading and linting only.
"""

from __future__ import annotations

# <imports>
from numba import njit

from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def ve_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """k₂ on the one segment (before the pulley splits the fibre) and the decay 1/τ."""
    kb = c[R_VE_K] if c[R_VE_ON] > 0.0 else 0.0
    c[D_KB1], c[D_KB2] = kb, kb
    if c[R_VE_ON] > 0.0:
        c[D_RELAX] = 1.0 / c[R_VE_TAU]
        real = max(real, c[D_RELAX])
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def ve_branch(c, y, q1, q2):  # type: ignore[no-untyped-def]
    """The branch forces, added to each segment's tension law."""
    return y[Y_Q1], y[Y_Q2]


@njit(cache=True, error_model="numpy")
def ve_rates(c, y, sg, t1, t2, zd):  # type: ignore[no-untyped-def]
    """(q̇₁, q̇₂): the branch is stretched with its segment while taut and relaxes."""
    dq1, dq2 = 0.0, 0.0
    if c[R_VE_ON] > 0.0:
        dq1 = (c[D_KB1] * sg[4] if c[S_TAUT1] > 0.0 else 0.0) - c[D_RELAX] * y[Y_Q1]
        if c[D_NSEG] > 1.5:
            dq2 = (c[D_KB2] * sg[5] if c[S_TAUT2] > 0.0 else 0.0) - c[D_RELAX] * y[Y_Q2]
    return dq1, dq2


@njit(cache=True, error_model="numpy")
def ve_start_state(c, x, xd, u, v, force, taut, m):  # type: ignore[no-untyped-def]
    """k₂ times the elongation high-passed with τ (the measured history, in m's I_HP)."""
    return c[D_KB1] * m[I_HP], c[D_KB2] * m[I_HP]
