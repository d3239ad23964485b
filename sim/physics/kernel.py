"""The compiled model's head: its layout, state helpers and constants (source text only).

The model is one text: this head, ``fibre`` (the fibre in one segment or two, the
weight, the friction table: constants, forces, right-hand side), ``integrator`` (RK4 /
ETDRK4 steps split at located events, substeps), ``runners`` (from rest, batch, segments,
chained, block by block), then each composed term's ``terms.py`` (an added effect's: the
compiled functions of its one file). Never imported as itself: ``sim.physics.compose``
writes it, composed for a set of terms, into one hash-named module (the head's marked
blocks: the layout's constants, the state's tuple helpers, the terms' hook calls;
``fibre``'s: the added effects' forces; the splice sites of ``fibre`` and
``integrator``: the bodies of the composed terms' hooks on the right-hand side's path,
``kernel_source.SPLICED``). The empty set is the baseline of STAND.md §2; the union has
every built-in term; an effect switched off adds exact zeros (bit for bit the baseline).

The baseline (state u, v: the weight's displacement up the incline and its velocity).
The drive position x is given at the sample times and is linear inside each sample
interval, so every RK4 step sees a smooth right-hand side. The fibre is *taut*
(T = k·δ + c·δ̇) or *slack* (T = 0), switched by events located inside the step: taut →
slack when k·δ + c·δ̇ falls through 0 (T is continuous there); slack → taut when δ rises
through 0 (T jumps by c·δ̇), or when δ > 0 and k·δ + c·δ̇ rises through 0. The friction
law has branches too: sliding up (v ≥ v_reg), sliding down (v ≤ −v_reg) and the linear
regularisation band between; at the top of a free flight the weight crosses the band
(2 mm/s wide) in a fraction of a step, and a step straddling it would see friction flip
sign inside one RK4 step — a first-order error that decides when the next snatch
happens. So the branch too is held fixed within a step and switched at located crossings
of v = ±v_reg. The step is split at the earliest located switch and each part integrated
with its own right-hand side, so neither the jump nor the kinks cost the method its
order; crossings are found on the cubic Hermite interpolant of the step (fourth order).
Time is i·dt, never summed.

The effects' terms generalise the events from one fibre to up to two fibre *segments*
(drive side and weight side, split by the pulley when it has its own degree of freedom),
each taut (T = kδ + cδ̇ + q) or slack, re-checked at every step's start. Their states
(``layout.STATES``): pulley rim displacement s, ṡ; Maxwell branch forces q₁, q₂;
string-mode amplitudes and rates a₁, ȧ₁ (drive span), a₂, ȧ₂ (weight span); LuGre
bristle z. The run's constants live in one array c (``layout``): the parameter row,
derived constants, the discrete state (taut flags, friction branch, pulley-jump seat and
slack episode, bearing presliding; the added effects' slots) and the friction table.
Stiff terms raise the substeps (``_substeps``) and take the exponential step where it pays.

Speed: the hot functions take c and scalars or tuples only; passing arrays to small
jitted functions costs 7 machine words per array per call (measured: 60 → 9 ms for 10 s
at 2 kHz). A term that is out of the set is not written in, and the second segment's
branches are pruned at compile time (``SEGMENTS``): the baseline runs on two states. The
hooks on the right-hand side's path are written in place, not called (``SPLICED``:
called, they made the union 3–4.5× slower). All numba code of the model is composed into
one text on purpose: numba's cache does not notice changes in jitted functions or
constants imported from other modules; a composed module's name is a hash of its whole
text instead. The parts' and the terms' import blocks are for reading and linting only.
"""

from __future__ import annotations

# The parts' imports, once for the composed module (theirs are dropped there).
import math  # noqa: F401

import numpy as np  # noqa: F401
from numba import njit, prange  # noqa: F401

# <layout>: ``sim.physics.compose`` writes the composed set's constants here, as literals
# (``layout.constants``); this file, never run as itself, reads the union's.
from sim.physics.layout import *

# Which terms the set composes (1: in): a term that is out is pruned at compile time.
ON_VE, ON_TV, ON_PJ, ON_PI, ON_SS, ON_SL, ON_X, ON_ANY = 1, 1, 1, 1, 1, 1, 1, 1
SEGMENTS = 2  # the most fibre segments the set has (the pulley's rim splits the fibre)
# </layout>

# <state>: ``kernel_source.state_block`` writes the set's tuple helpers here; what follows
# is the union's (a test holds them equal), for reading: this file never runs as itself.
ZERO = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
NCARRY = 5  # states carried from segment to segment


@njit(cache=True, error_model="numpy")
def _axpy(y, a, k):  # type: ignore[no-untyped-def]
    """y + a·k, component by component."""
    return (
        y[0] + a * k[0], y[1] + a * k[1], y[2] + a * k[2], y[3] + a * k[3], y[4] + a * k[4],
        y[5] + a * k[5], y[6] + a * k[6], y[7] + a * k[7], y[8] + a * k[8], y[9] + a * k[9],
        y[10] + a * k[10],
    )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _combine(y, a, k1, k2, k3, k4):  # type: ignore[no-untyped-def]
    """The RK4 update y + a·(k1 + 2k2 + 2k3 + k4), component by component."""
    return (
        y[0] + a * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
        y[1] + a * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        y[2] + a * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]),
        y[3] + a * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3]),
        y[4] + a * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4]),
        y[5] + a * (k1[5] + 2.0 * k2[5] + 2.0 * k3[5] + k4[5]),
        y[6] + a * (k1[6] + 2.0 * k2[6] + 2.0 * k3[6] + k4[6]),
        y[7] + a * (k1[7] + 2.0 * k2[7] + 2.0 * k3[7] + k4[7]),
        y[8] + a * (k1[8] + 2.0 * k2[8] + 2.0 * k3[8] + k4[8]),
        y[9] + a * (k1[9] + 2.0 * k2[9] + 2.0 * k3[9] + k4[9]),
        y[10] + a * (k1[10] + 2.0 * k2[10] + 2.0 * k3[10] + k4[10]),
    )


@njit(cache=True, error_model="numpy")
def _hermite(a, b, d, e, h, y0, f0, y1, f1):  # type: ignore[no-untyped-def]
    """The cubic Hermite interpolant's state from its four weights."""
    return (
        a * y0[0] + b * h * f0[0] + d * y1[0] + e * h * f1[0],
        a * y0[1] + b * h * f0[1] + d * y1[1] + e * h * f1[1],
        a * y0[2] + b * h * f0[2] + d * y1[2] + e * h * f1[2],
        a * y0[3] + b * h * f0[3] + d * y1[3] + e * h * f1[3],
        a * y0[4] + b * h * f0[4] + d * y1[4] + e * h * f1[4],
        a * y0[5] + b * h * f0[5] + d * y1[5] + e * h * f1[5],
        a * y0[6] + b * h * f0[6] + d * y1[6] + e * h * f1[6],
        a * y0[7] + b * h * f0[7] + d * y1[7] + e * h * f1[7],
        a * y0[8] + b * h * f0[8] + d * y1[8] + e * h * f1[8],
        a * y0[9] + b * h * f0[9] + d * y1[9] + e * h * f1[9],
        a * y0[10] + b * h * f0[10] + d * y1[10] + e * h * f1[10],
    )


@njit(cache=True, error_model="numpy")
def _tuple_of(state):  # type: ignore[no-untyped-def]
    """The state tuple from its array."""
    return (
        state[0], state[1], state[2], state[3], state[4], state[5], state[6], state[7],
        state[8], state[9], state[10],
    )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _state(u, v, s, sd, q1, q2, a1, ad1, a2, ad2, z):  # type: ignore[no-untyped-def]
    """The set's state from every state's value (those it lacks are dropped)."""
    return (u, v, s, sd, q1, q2, a1, ad1, a2, ad2, z)


@njit(cache=True, error_model="numpy")
def _stiff_set(y, sd, z):  # type: ignore[no-untyped-def]
    """y with the rim's velocity and the bristle replaced."""
    return (y[0], y[1], y[2], sd, y[4], y[5], y[6], y[7], y[8], y[9], z)


@njit(cache=True, error_model="numpy")
def _carry_out(state, carried):  # type: ignore[no-untyped-def]
    """The carried states of a state array."""
    carried[0] = state[6]
    carried[1] = state[7]
    carried[2] = state[8]
    carried[3] = state[9]
    carried[4] = state[10]


@njit(cache=True, error_model="numpy")
def _with_carried(y, carried):  # type: ignore[no-untyped-def]
    """y with the carried states replaced."""
    return (
        y[0], y[1], y[2], y[3], y[4], y[5], carried[0], carried[1], carried[2], carried[3],
        carried[4],
    )  # fmt: skip


# </state>

# <hooks>: ``kernel_source.hooks_block`` writes the composed terms' hook calls here; what
# follows is the union's (a test holds them equal), for reading and linting.
from sim.effects.fibre_pulley_jump.terms import (
    pj_after_part,
    pj_extension,
    pj_given_at,
    pj_given_end,
    pj_given_start,
    pj_start,
)
from sim.effects.fibre_transverse_vibration.terms import (
    tv_extension,
    tv_pack,
    tv_rates,
    tv_rest,
    tv_start_state,
    tv_substeps,
)
from sim.effects.fibre_viscoelastic.terms import ve_branch, ve_pack, ve_rates, ve_start_state
from sim.effects.pulley_inertia_friction.terms import (
    pi_pack,
    pi_rates,
    pi_segments,
    pi_settle,
    pi_start,
    pi_start_state,
    pi_substeps,
)
from sim.effects.side_load_friction.terms import sl_friction, sl_pack, sl_substeps, sl_zoned
from sim.effects.stick_slip_friction.terms import (
    ss_decay,
    ss_friction_law,
    ss_pack,
    ss_rates,
    ss_replaces_friction,
    ss_start_state,
    ss_substeps,
)


@njit(cache=True, error_model="numpy")
def _terms_on(c):  # type: ignore[no-untyped-def]
    """How many of the composed terms are on (> 0: any)."""
    return 0.0 + c[R_VE_ON] + c[R_TV_ON] + c[R_PJ_ON] + c[R_PI_ON] + c[R_SS_ON] + c[R_SL_ON]


@njit(cache=True, error_model="numpy")
def _terms_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """The composed terms' ``pack`` hooks."""
    osc, osc_exp, real = ve_pack(c, osc, osc_exp, real)
    osc, osc_exp, real = tv_pack(c, osc, osc_exp, real)
    osc, osc_exp, real = pi_pack(c, osc, osc_exp, real)
    osc, osc_exp, real = ss_pack(c, osc, osc_exp, real)
    osc, osc_exp, real = sl_pack(c, osc, osc_exp, real)
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def _terms_replaces_friction(c):  # type: ignore[no-untyped-def]
    """The composed terms' ``replaces_friction`` hooks."""
    said = False
    this = ss_replaces_friction(c)
    said = said or this
    return said


@njit(cache=True, error_model="numpy")
def _terms_zoned(c):  # type: ignore[no-untyped-def]
    """The composed terms' ``zoned`` hooks."""
    said = False
    this = sl_zoned(c)
    said = said or this
    return said


@njit(cache=True, error_model="numpy")
def _terms_extension(c, y, ext1, rate1, ext2, rate2):  # type: ignore[no-untyped-def]
    """The composed terms' ``extension`` hooks."""
    ext1, rate1, ext2, rate2 = tv_extension(c, y, ext1, rate1, ext2, rate2)
    ext1, rate1, ext2, rate2 = pj_extension(c, y, ext1, rate1, ext2, rate2)
    return ext1, rate1, ext2, rate2


@njit(cache=True, error_model="numpy")
def _terms_branch(c, y, q1, q2):  # type: ignore[no-untyped-def]
    """The composed terms' ``branch`` hooks."""
    q1, q2 = ve_branch(c, y, q1, q2)
    return q1, q2


@njit(cache=True, error_model="numpy")
def _terms_friction_law(c, y, v, replaced, fric, zd):  # type: ignore[no-untyped-def]
    """The composed terms' ``friction_law`` hooks."""
    replaced, fric, zd = ss_friction_law(c, y, v, replaced, fric, zd)
    return replaced, fric, zd


@njit(cache=True, error_model="numpy")
def _terms_friction(c, v, zone, t2, fric):  # type: ignore[no-untyped-def]
    """The composed terms' ``friction`` hooks."""
    fric = sl_friction(c, v, zone, t2, fric)
    return fric


@njit(cache=True, error_model="numpy")
def _terms_weight(c, y, v, t2, drive):  # type: ignore[no-untyped-def]
    """The composed terms' ``weight`` hooks."""
    return drive


@njit(cache=True, error_model="numpy")
def _terms_decay(c, v, rate):  # type: ignore[no-untyped-def]
    """The composed terms' ``decay`` hooks."""
    rate = ss_decay(c, v, rate)
    return rate


@njit(cache=True, error_model="numpy")
def _terms_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp):  # type: ignore[no-untyped-def]
    """The composed terms' ``substeps`` hooks."""
    osc, osc_exp, real, real_exp = tv_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp)
    osc, osc_exp, real, real_exp = pi_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp)
    osc, osc_exp, real, real_exp = ss_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp)
    osc, osc_exp, real, real_exp = sl_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp)
    return osc, osc_exp, real, real_exp


@njit(cache=True, error_model="numpy")
def _terms_after_part(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """The composed terms' ``after_part`` hooks."""
    pj_after_part(c, y, x, xd, h)


@njit(cache=True, error_model="numpy")
def _terms_given_start(c, given):  # type: ignore[no-untyped-def]
    """The composed terms' ``given_start`` hooks."""
    said = False
    this = pj_given_start(c, given)
    said = said or this
    return said


@njit(cache=True, error_model="numpy")
def _terms_given_at(c, value):  # type: ignore[no-untyped-def]
    """The composed terms' ``given_at`` hooks."""
    pj_given_at(c, value)


@njit(cache=True, error_model="numpy")
def _terms_given_end(c):  # type: ignore[no-untyped-def]
    """The composed terms' ``given_end`` hooks."""
    pj_given_end(c)


@njit(cache=True, error_model="numpy")
def _terms_start(c, y, x, xd, m):  # type: ignore[no-untyped-def]
    """The composed terms' ``start`` hooks."""
    pj_start(c, y, x, xd, m)
    pi_start(c, y, x, xd, m)


@njit(cache=True, error_model="numpy")
def _terms_segments(  # type: ignore[no-untyped-def]
    c, y, xa, xb, xd, n, ext1, rate1, ext2, rate2, q1, q2, d1, f1, d2, f2, dd1, dd2
):
    """The composed terms' ``segments`` hooks."""
    d1, f1, d2, f2, dd1, dd2 = pi_segments(
        c, y, xa, xb, xd, n, ext1, rate1, ext2, rate2, q1, q2, d1, f1, d2, f2, dd1, dd2
    )
    return d1, f1, d2, f2, dd1, dd2


@njit(cache=True, error_model="numpy")
def _terms_settle(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """The composed terms' ``settle`` hooks."""
    pi_settle(c, y, x, xd, h)


@njit(cache=True, error_model="numpy")
def _terms_rest(c):  # type: ignore[no-untyped-def]
    """The whole state: the composed terms' ``rest`` hooks give their own."""
    (
        r_a1,
        r_ad1,
        r_a2,
        r_ad2,
    ) = tv_rest(c)
    return _state(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, r_a1, r_ad1, r_a2, r_ad2, 0.0)


@njit(cache=True, error_model="numpy")
def _terms_rates(c, y, sg, t1, t2, zd, v, acc):  # type: ignore[no-untyped-def]
    """The whole state: the composed terms' ``rates`` hooks give their own."""
    (
        r_q1,
        r_q2,
    ) = ve_rates(c, y, sg, t1, t2, zd)
    (
        r_a1,
        r_ad1,
        r_a2,
        r_ad2,
    ) = tv_rates(c, y, sg, t1, t2, zd)
    (
        r_s,
        r_sd,
    ) = pi_rates(c, y, sg, t1, t2, zd)
    (r_z,) = ss_rates(c, y, sg, t1, t2, zd)
    return _state(v, acc, r_s, r_sd, r_q1, r_q2, r_a1, r_ad1, r_a2, r_ad2, r_z)


@njit(cache=True, error_model="numpy")
def _terms_start_state(c, x, xd, u, v, force, taut, m):  # type: ignore[no-untyped-def]
    """The whole state: the composed terms' ``start_state`` hooks give their own."""
    (
        r_q1,
        r_q2,
    ) = ve_start_state(c, x, xd, u, v, force, taut, m)
    (
        r_a1,
        r_ad1,
        r_a2,
        r_ad2,
    ) = tv_start_state(c, x, xd, u, v, force, taut, m)
    (
        r_s,
        r_sd,
    ) = pi_start_state(c, x, xd, u, v, force, taut, m)
    (r_z,) = ss_start_state(c, x, xd, u, v, force, taut, m)
    return _state(u, v, r_s, r_sd, r_q1, r_q2, r_a1, r_ad1, r_a2, r_ad2, r_z)


# </hooks>

NSUB_MAX = 64  # substeps per sample interval at most
EXP_COST = 1.3  # an exponential step (_etdrk4) costs about this many RK4 steps (measured)
MAX_SWITCH = 8  # regime switches per segment located inside one step (the baseline's 8)
BRISTLE_SWING = 0.1  # relative change of the bristle's relaxation rate within one ETD step
