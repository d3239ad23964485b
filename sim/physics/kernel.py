"""The compiled model: one integrator, its runners, the built-in terms (source text only).

Never imported as itself: ``sim.physics.compose`` writes it, composed for a set of terms,
into a hash-named module (its three marked blocks: the layout's constants, the state's
tuple helpers, the added effects' forces). The empty set is the baseline of STAND.md §2;
the union has every built-in term, and an effect switched off in a row adds exact zeros,
so both give the baseline's numbers bit for bit with every effect off.

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
slack episode, bearing presliding) and the friction table. Stiff terms raise the RK4
substeps per sample from estimates of their fastest rates (``_substeps``) and take the
exponential step (``_etdrk4``) where it pays.

Speed: the hot functions take c and scalars or tuples only; passing arrays to small
jitted functions costs 7 machine words per array per call (measured: 60 → 9 ms for 10 s
at 2 kHz). A term that is out of the set is pruned at compile time (``ON_*``), so the
baseline runs on two states without the terms' branches. All numba code of the model is
in this one text on purpose: numba's cache does not notice changes in jitted functions
or constants imported from other modules; a composed module's name is a hash of its
whole text instead. Each effect's parameters, ranges and hooks are in its own module
(``sim/effects/*.py``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

# <layout>: ``sim.physics.compose`` writes the composed set's constants here, as literals
# (``layout.constants``); this file, never run as itself, reads the union's.
from sim.physics.layout import (
    C_TABLE,
    D_AR1,
    D_AR1SQ,
    D_AR2,
    D_AR2SQ,
    D_C1,
    D_C2,
    D_CM1,
    D_CM2,
    D_D10,
    D_D20,
    D_DYN,
    D_F1,
    D_F2,
    D_FB0,
    D_FBL,
    D_K1,
    D_K2,
    D_KB1,
    D_KB2,
    D_MP,
    D_NSEG,
    D_OSC,
    D_REAL,
    D_RELAX,
    D_SIG0,
    D_SIG1,
    D_SIGP,
    D_SL,
    D_SS_ON,
    D_ST1,
    D_ST2,
    D_T0,
    D_W1,
    D_W2,
    D_ZONES,
    E_H,
    E_ON,
    E_OSC,
    E_RATE,
    E_RIM,
    E_W,
    I_DEPTH,
    I_F,
    I_HP,
    I_LBASE,
    I_LOFF,
    I_SLACKT,
    I_U,
    I_V,
    N_ROW,
    NY,
    P_DAMP,
    P_FRICTION_N,
    P_GRAVITY_N,
    P_MASS,
    P_PRELOAD,
    P_PROJ,
    P_STIFF,
    P_VREG,
    R_DRIVE_SPAN,
    R_FIBRE_LEN,
    R_FREE_SPAN,
    R_G_PERP_WEIGHT_SPAN,
    R_GRAVITY,
    R_LIN_DENSITY,
    R_PI_J,
    R_PI_LOAD,
    R_PI_ON,
    R_PI_PRESLIDE,
    R_PI_TORQUE,
    R_PJ_DEPTH,
    R_PJ_DWELL,
    R_PJ_ON,
    R_PJ_ONSET,
    R_PJ_SEATS,
    R_PJ_STEP,
    R_RADIUS,
    R_SIN_BETA,
    R_SIN_HALF_WRAP,
    R_SL_MU,
    R_SL_ON,
    R_SS_EXP,
    R_SS_ON,
    R_SS_RATIO,
    R_SS_SIGMA,
    R_SS_VS,
    R_TV_LOAD,
    R_TV_ON,
    R_TV_TILT,
    R_TV_ZETA,
    R_VE_K,
    R_VE_ON,
    R_VE_TAU,
    R_X_ON,
    S_DEPTH,
    S_LBASE,
    S_LOFF,
    S_PS0,
    S_PZ,
    S_RECSEAT,
    S_SLACKT,
    S_TAUT1,
    S_TAUT2,
    S_ZONE,
    Y_A1,
    Y_A2,
    Y_AD1,
    Y_AD2,
    Y_Q1,
    Y_Q2,
    Y_S,
    Y_SD,
    Y_U,
    Y_V,
    Y_Z,
)  # fmt: skip

# Which terms the set composes (1: in): a term that is out is pruned at compile time.
ON_VE, ON_TV, ON_PJ, ON_PI, ON_SS, ON_SL, ON_X, ON_ANY = 1, 1, 1, 1, 1, 1, 1, 1
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

NSUB_MAX = 64  # substeps per sample interval at most
EXP_COST = 1.3  # an exponential step (_etdrk4) costs about this many RK4 steps (measured)
MAX_SWITCH = 8  # regime switches per segment located inside one step (the baseline's 8)
BRISTLE_SWING = 0.1  # relative change of the bristle's relaxation rate within one ETD step


@njit(cache=True, error_model="numpy")
def _mu(speed, c):  # type: ignore[no-untyped-def]
    """μ(speed) from the PCHIP table in c; the end pieces extend smoothly past the knots."""
    n = int(c[C_TABLE])
    kn = C_TABLE + 1
    co = kn + n
    m = n - 1
    if speed >= c[kn + n - 1]:
        s = c[kn + n - 1] - c[kn + n - 2]
        i = n - 2
    else:
        i = 0
        while i < n - 2 and speed > c[kn + i + 1]:
            i += 1
        s = speed - c[kn + i]
    return ((c[co + i] * s + c[co + m + i]) * s + c[co + 2 * m + i]) * s + c[co + 3 * m + i]


@njit(cache=True, error_model="numpy")
def _zone(v, c):  # type: ignore[no-untyped-def]
    """Friction branch: +1 sliding up, -1 sliding down, 0 inside the regularisation band."""
    if c[D_ZONES] == 0.0:
        return 0
    if v >= c[P_VREG]:
        return 1
    if v <= -c[P_VREG]:
        return -1
    return 0


@njit(cache=True, error_model="numpy")
def _friction(v, zone, c):  # type: ignore[no-untyped-def]
    # The branch is fixed for the whole step (an RK stage may stray just past v_reg): each
    # branch is smooth, and the switch between branches is an event like the slack one.
    fn = c[P_FRICTION_N]
    if fn == 0.0:
        return 0.0
    if zone > 0:
        return fn * _mu(v, c)
    if zone < 0:
        return -fn * _mu(-v, c)
    vreg = c[P_VREG]
    return fn * _mu(vreg, c) * v / vreg


@njit(cache=True, error_model="numpy")
def _string_modes(c, t0):  # type: ignore[no-untyped-def]
    """Constants of the first string mode of each free span (0 drive side, 1 weight side)."""
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


@njit(cache=True, error_model="numpy")
def pack(row, knots, coef):  # type: ignore[no-untyped-def]
    """The constants array c of one run: row, derived constants, rest state, table."""
    n = knots.shape[0]
    c = np.zeros(C_TABLE + 1 + n + 4 * (n - 1))
    for i in range(N_ROW):  # scalar loops: slice assignment costs seconds of compile time
        c[i] = row[i]
    c[C_TABLE] = n
    for i in range(n):
        c[C_TABLE + 1 + i] = knots[i]
    for r in range(4):
        for i in range(n - 1):
            c[C_TABLE + 1 + n + r * (n - 1) + i] = coef[r, i]
    k, damp = c[P_STIFF], c[P_DAMP]
    t0 = c[P_GRAVITY_N] / c[P_PROJ]
    c[D_T0] = t0
    c[D_NSEG] = 1.0
    c[D_K1], c[D_C1], c[D_K2], c[D_C2] = k, damp, k, damp
    c[D_D10], c[D_D20] = c[P_PRELOAD], c[P_PRELOAD]
    kb = c[R_VE_K] if c[R_VE_ON] > 0.0 else 0.0
    c[D_KB1], c[D_KB2] = kb, kb
    osc, real = 0.0, 0.0
    if c[R_PI_ON] > 0.0:  # two segments; the wrapped arc is shared half and half
        total, l1, l2 = c[R_FIBRE_LEN], c[R_DRIVE_SPAN], c[R_FREE_SPAN]
        half = 0.5 * (total - l1 - l2)
        f1, f2 = total / (l1 + half), total / (l2 + half)
        c[D_NSEG] = 2.0
        c[D_K1], c[D_C1], c[D_K2], c[D_C2] = k * f1, damp * f1, k * f2, damp * f2
        c[D_D10], c[D_D20] = t0 / (k * f1), t0 / (k * f2)
        c[D_KB1], c[D_KB2] = kb * f1, kb * f2
        r = c[R_RADIUS]
        c[D_MP] = c[R_PI_J] / (r * r)
        c[D_FB0] = c[R_PI_TORQUE] / r
        c[D_FBL] = c[R_PI_LOAD] * c[R_SIN_HALF_WRAP]
        c[D_SIGP] = (c[D_FB0] + 2.0 * c[D_FBL] * t0) / c[R_PI_PRESLIDE]
        stiff = c[D_K1] + c[D_K2] + c[D_KB1] + c[D_KB2] + c[D_SIGP]
        osc = math.sqrt(stiff / c[D_MP])
        c[E_RIM] = (c[D_C1] + c[D_C2]) / c[D_MP]
    if c[R_VE_ON] > 0.0:
        c[D_RELAX] = 1.0 / c[R_VE_TAU]
        real = max(real, c[D_RELAX])
    if c[R_TV_ON] > 0.0:
        _string_modes(c, t0)
    if c[R_SS_ON] > 0.0 and c[P_FRICTION_N] > 0.0:  # LuGre needs a friction table
        c[D_SS_ON] = 1.0
        c[D_SIG0] = c[R_SS_SIGMA]
        c[D_SIG1] = 2.0 * math.sqrt(c[R_SS_SIGMA] * c[P_MASS])
        osc = max(osc, math.sqrt(c[R_SS_SIGMA] / c[P_MASS]))
    c[E_OSC] = osc
    if c[D_SS_ON] > 0.0:
        # What an exact relaxation leaves to RK4: the damping σ₁·shape·ż couples the
        # weight to it at σ₁·shape(v)·σ₀|v|/g(v) per metre of bristle, against σ₀; its
        # worst is where |v|·shape(v) peaks, at |v/v_s| = δ^(−1/δ). Measured (σ₀ 1e6 N/m,
        # v_s 3 cm/s): at |λ|·h = 0.5 for it the force is off by 0.06 N, at 0.25 by 0.006 N.
        power = c[R_SS_EXP]
        v_peak = c[R_SS_VS] * power ** (-1.0 / power)
        shape = math.exp(-1.0 / power)
        g_peak = c[P_FRICTION_N] * _mu(v_peak, c) * (1.0 + c[R_SS_RATIO] * shape)
        coupled = c[D_SIG1] * shape * c[R_SS_SIGMA] * v_peak / g_peak - c[R_SS_SIGMA]
        c[E_OSC] = max(osc, 2.0 * math.sqrt(max(coupled, 0.0) / c[P_MASS]))
    if c[R_SL_ON] > 0.0:
        c[D_SL] = c[R_SL_MU] * c[R_SIN_BETA]
    c[D_OSC], c[D_REAL] = osc, real
    on = c[R_VE_ON] + c[R_TV_ON] + c[R_PJ_ON] + c[R_PI_ON] + c[R_SS_ON] + c[R_SL_ON] + c[R_X_ON]
    c[D_DYN] = 1.0 if on > 0.0 else 0.0
    table = c[P_FRICTION_N] != 0.0 and c[D_SS_ON] == 0.0
    c[D_ZONES] = 1.0 if table or c[R_SL_ON] > 0.0 else 0.0
    c[S_TAUT1], c[S_TAUT2] = 1.0, 1.0
    c[E_H] = -1.0  # no rim weights yet
    return c


@njit(cache=True, error_model="numpy")
def rest_state(c):  # type: ignore[no-untyped-def]
    """Static rest: weight and pulley still, fibre taut at T₀, strings at their gravity sag."""
    if ON_TV and c[R_TV_ON] > 0.0:
        return _state(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, c[D_AR1], 0.0, c[D_AR2], 0.0, 0.0)
    return ZERO


@njit(cache=True, error_model="numpy")
def _segments(c, y, xa, xb, xd):  # type: ignore[no-untyped-def]
    """(δ₁, F₁, δ₂, F₂, δ̇₁, δ̇₂): each segment's elongation and tension law at x = xa + xb."""
    n = c[P_PROJ]
    ext1, rate1, ext2, rate2 = 0.0, 0.0, 0.0, 0.0
    if ON_TV and c[R_TV_ON] > 0.0:
        a1, a2 = y[Y_A1], y[Y_A2]
        ext1 = c[D_ST1] * (a1 * a1 - c[D_AR1SQ])
        rate1 = 2.0 * c[D_ST1] * a1 * y[Y_AD1]
        ext2 = c[D_ST2] * (a2 * a2 - c[D_AR2SQ])
        rate2 = 2.0 * c[D_ST2] * a2 * y[Y_AD2]
    if ON_PJ and c[R_PJ_ON] > 0.0:
        ext2 += c[S_LOFF]
    q1, q2 = (y[Y_Q1], y[Y_Q2]) if ON_VE else (0.0, 0.0)  # + 0.0: the union's sum
    if not ON_PI or c[D_NSEG] < 1.5:
        d = c[D_D10] + xa + xb - n * y[Y_U] + (ext1 + ext2)
        dd = xd - n * y[Y_V] + (rate1 + rate2)
        f = c[D_K1] * d + c[D_C1] * dd + q1
        return d, f, d, f, dd, dd
    d1 = c[D_D10] + xa + xb - y[Y_S] + ext1
    dd1 = xd - y[Y_SD] + rate1
    d2 = c[D_D20] + y[Y_S] - n * y[Y_U] + ext2
    dd2 = y[Y_SD] - n * y[Y_V] + rate2
    f1 = c[D_K1] * d1 + c[D_C1] * dd1 + q1
    f2 = c[D_K2] * d2 + c[D_C2] * dd2 + q2
    return d1, f1, d2, f2, dd1, dd2


@njit(cache=True, error_model="numpy")
def _tensions(c, sg):  # type: ignore[no-untyped-def]
    t1 = sg[1] if c[S_TAUT1] > 0.0 else 0.0
    if not ON_PI or c[D_NSEG] < 1.5:
        return t1, t1
    return t1, (sg[3] if c[S_TAUT2] > 0.0 else 0.0)


@njit(cache=True, error_model="numpy")
def _bearing_limit(c, t1, t2):  # type: ignore[no-untyped-def]
    """Largest bearing presliding displacement at these tensions, m."""
    return (c[D_FB0] + c[D_FBL] * (max(t1, 0.0) + max(t2, 0.0))) / c[D_SIGP]


# <added-force>: ``sim.physics.compose`` replaces this function in a composed kernel by
# the sum of the added effects' forces; in this file no effect is added.
@njit(cache=True, error_model="numpy")
def _added_force(c, y, t2):  # type: ignore[no-untyped-def]
    """Force on the weight (N, up the incline) of the effects added outside this file."""
    return 0.0


# </added-force>


@njit(cache=True, error_model="numpy")
def _stribeck(v, c):  # type: ignore[no-untyped-def]
    """The Stribeck curve's shape exp(−|v/v_s|^δ): 1 at rest, 0 when sliding fast."""
    r = abs(v) / c[R_SS_VS]
    if c[R_SS_EXP] == 2.0:  # the Gaussian (the default): no power function per step
        return math.exp(-r * r)
    return math.exp(-(r ** c[R_SS_EXP]))


@njit(cache=True, error_model="numpy")
def _rhs(c, y, xa, xd):  # type: ignore[no-untyped-def]
    """dy/dt at drive position xa (rate xd) in the current regimes."""
    sg = _segments(c, y, xa, 0.0, xd)
    t1, t2 = _tensions(c, sg)
    v = y[Y_V]
    zone = int(c[S_ZONE])
    zd = 0.0
    if ON_SS and c[D_SS_ON] > 0.0:  # LuGre replaces the table's friction
        shape = _stribeck(v, c)
        g = c[P_FRICTION_N] * _mu(abs(v), c) * (1.0 + c[R_SS_RATIO] * shape)
        zd = v - c[D_SIG0] * abs(v) * y[Y_Z] / g
        fric = c[D_SIG0] * y[Y_Z] + c[D_SIG1] * shape * zd
    else:
        fric = _friction(v, zone, c)
    if ON_SL and c[R_SL_ON] > 0.0:
        side = c[D_SL] * max(t2, 0.0)
        fric += side * zone if zone != 0 else side * v / c[P_VREG]
    drive = -c[P_GRAVITY_N] - fric
    drive += c[P_PROJ] * t2  # + 0.0 while slack: the baseline's sum, bit for bit
    if ON_X and c[R_X_ON] > 0.0:
        drive += _added_force(c, y, t2)
    acc = drive / c[P_MASS]
    s_acc, dq1, dq2, aa1, aa2 = 0.0, 0.0, 0.0, 0.0, 0.0
    if ON_PI and c[D_NSEG] > 1.5:
        fp = 0.0
        if c[D_SIGP] > 0.0:
            zmax = _bearing_limit(c, t1, t2)
            fp = c[D_SIGP] * min(max(c[S_PZ] + y[Y_S] - c[S_PS0], -zmax), zmax)
        s_acc = (t1 - t2 - fp) / c[D_MP]
    if ON_VE and c[R_VE_ON] > 0.0:
        dq1 = (c[D_KB1] * sg[4] if c[S_TAUT1] > 0.0 else 0.0) - c[D_RELAX] * y[Y_Q1]
        if c[D_NSEG] > 1.5:
            dq2 = (c[D_KB2] * sg[5] if c[S_TAUT2] > 0.0 else 0.0) - c[D_RELAX] * y[Y_Q2]
    if ON_TV and c[R_TV_ON] > 0.0:
        aa1 = c[D_F1] - c[D_W1] * max(t1, 0.0) * y[Y_A1] - c[D_CM1] * y[Y_AD1]
        aa2 = c[D_F2] - c[D_W2] * max(t2, 0.0) * y[Y_A2] - c[D_CM2] * y[Y_AD2]
    sd = y[Y_SD] if ON_PI else 0.0
    ad1, ad2 = (y[Y_AD1], y[Y_AD2]) if ON_TV else (0.0, 0.0)
    return _state(v, acc, sd, s_acc, dq1, dq2, ad1, aa1, ad2, aa2, zd)


@njit(cache=True, error_model="numpy")
def _rk4(c, y, x0, xd, h):  # type: ignore[no-untyped-def]
    """One RK4 step of length h from y: (new state, dy/dt at the start)."""
    k1 = _rhs(c, y, x0, xd)
    if ON_ANY and c[E_ON] > 0.0:
        return _etdrk4(c, y, x0, xd, h, k1), k1
    xm = x0 + 0.5 * h * xd
    k2 = _rhs(c, _axpy(y, 0.5 * h, k1), xm, xd)
    k3 = _rhs(c, _axpy(y, 0.5 * h, k2), xm, xd)
    k4 = _rhs(c, _axpy(y, h, k3), x0 + h * xd, xd)
    return _combine(y, h / 6.0, k1, k2, k3, k4), k1


@njit(cache=True, error_model="numpy")
def _decay_rates(c, y, v):  # type: ignore[no-untyped-def]
    """The stiff linear decays integrated exactly (``_etdrk4``), 1/s.

    The rim's velocity under the damping of its taut segments, (c₁ + c₂)/(J/r²) — up to
    1e5/s for a light pulley —, and the LuGre bristle's relaxation σ₀|v|/g(v) while
    sliding, 1e4/s and more at speed, frozen at the weight's speed v (the step's middle,
    predicted: frozen at its start, a run at σ₀ = 1e6 N/m erred four times as much).
    """
    rim = 0.0
    if c[D_NSEG] > 1.5:
        damp = (c[D_C1] if c[S_TAUT1] > 0.0 else 0.0) + (c[D_C2] if c[S_TAUT2] > 0.0 else 0.0)
        rim = damp / c[D_MP]
    bristle = 0.0
    if c[D_SS_ON] > 0.0:
        g = c[P_FRICTION_N] * _mu(abs(v), c) * (1.0 + c[R_SS_RATIO] * _stribeck(v, c))
        bristle = c[D_SIG0] * abs(v) / g
    return rim, bristle


_INVERSE = tuple(1.0 / k if k else 0.0 for k in range(18))  # 1/k: the series multiplies


@njit(cache=True, error_model="numpy")
def _etd_weights(rate, h):  # type: ignore[no-untyped-def]
    """Cox–Matthews ETDRK4 weights of one decay rate λ over a step h.

    They are e^(−λh/2), (h/2)φ₁(−λh/2), e^(−λh), and h·b₁, h·b₂, h·b₄ with
    b₁ = φ₁ − 3φ₂ + 4φ₃, b₂ = 2φ₂ − 4φ₃, b₄ = 4φ₃ − φ₂ at z = −λh.
    φ₃(z) = Σ_j z^j/(j + 3)! by its series where the closed form cancels (|z| < 1), then
    φ₂ = 1/2 + zφ₃ and φ₁ = 1 + zφ₂; e^z − 1 = (e^(z/2) − 1)(e^(z/2) + 1) needs one expm1.
    """
    if rate == 0.0:  # RK4's own
        return 1.0, 0.5 * h, 1.0, h / 6.0, h / 3.0, h / 6.0
    z = -rate * h
    em = math.expm1(0.5 * z)
    e2 = 1.0 + em
    if z > -1.0:
        p3 = 1.0  # Horner: 3!·φ₃ = 1 + z/4·(1 + z/5·(1 + …)), to z^14 (error < 1e-15)
        for k in range(17, 3, -1):
            p3 = 1.0 + z * p3 * _INVERSE[k]
        p3 = p3 / 6.0
        p2 = 0.5 + z * p3
        p1 = 1.0 + z * p2
    else:
        p1 = em * (2.0 + em) / z
        p2 = (p1 - 1.0) / z
        p3 = (p2 - 0.5) / z
    return (
        e2, em / -rate, e2 * e2,
        h * (p1 - 3.0 * p2 + 4.0 * p3), h * (2.0 * p2 - 4.0 * p3), h * (4.0 * p3 - p2),
    )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _rim_weights(c, rate, h):  # type: ignore[no-untyped-def]
    """``_etd_weights`` of the rim, kept in c: its rate changes only with the regimes."""
    if rate != c[E_RATE] or h != c[E_H]:
        w = _etd_weights(rate, h)
        c[E_RATE], c[E_H] = rate, h
        for i in range(6):
            c[E_W + i] = w[i]
    return c[E_W], c[E_W + 1], c[E_W + 2], c[E_W + 3], c[E_W + 4], c[E_W + 5]


@njit(cache=True, error_model="numpy")
def _etdrk4(c, y, x0, xd, h, k1):  # type: ignore[no-untyped-def]
    """RK4 with the rim's velocity and the bristle by exponential time differencing.

    Their decays (``_decay_rates``) are linear in them: ẏᵢ = −λᵢyᵢ + Nᵢ(y). Cox and
    Matthews' ETDRK4 (J. Comput. Phys. 176, 2002) integrates −λᵢyᵢ exactly and keeps
    fixed points (the rim's quasi-static balance, the bristle's sliding deflection), so
    the substeps follow the slower dynamics instead of λᵢ; with λᵢ = 0 its stages are
    RK4's, and the other nine states take RK4's own. Used where it takes fewer substeps
    than RK4 (``_substeps``): its stages cost more.
    """
    ls, lz = _decay_rates(c, y, y[Y_V] + 0.5 * h * k1[Y_V])
    es2, ps, es, b1s, b2s, b4s = _rim_weights(c, ls, h)
    ez2, pz, ez, b1z, b2z, b4z = _etd_weights(lz, h)
    sd, z = y[Y_SD], y[Y_Z]
    n1s, n1z = k1[Y_SD] + ls * sd, k1[Y_Z] + lz * z
    xm = x0 + 0.5 * h * xd
    ya = _stiff_set(_axpy(y, 0.5 * h, k1), es2 * sd + ps * n1s, ez2 * z + pz * n1z)
    k2 = _rhs(c, ya, xm, xd)
    n2s, n2z = k2[Y_SD] + ls * ya[Y_SD], k2[Y_Z] + lz * ya[Y_Z]
    yb = _stiff_set(_axpy(y, 0.5 * h, k2), es2 * sd + ps * n2s, ez2 * z + pz * n2z)
    k3 = _rhs(c, yb, xm, xd)
    n3s, n3z = k3[Y_SD] + ls * yb[Y_SD], k3[Y_Z] + lz * yb[Y_Z]
    yc = _stiff_set(
        _axpy(y, h, k3),
        es2 * ya[Y_SD] + ps * (2.0 * n3s - n1s),
        ez2 * ya[Y_Z] + pz * (2.0 * n3z - n1z),
    )
    k4 = _rhs(c, yc, x0 + h * xd, xd)
    n4s, n4z = k4[Y_SD] + ls * yc[Y_SD], k4[Y_Z] + lz * yc[Y_Z]
    return _stiff_set(
        _combine(y, h / 6.0, k1, k2, k3, k4),
        es * sd + b1s * n1s + b2s * (n2s + n3s) + b4s * n4s,
        ez * z + b1z * n1z + b2z * (n2z + n3z) + b4z * n4z,
    )


# Event functions: which = 0 → δ of segment j, 1 → its tension law, 2 → v − v_reg,
# 3 → v + v_reg; evaluated on the cubic Hermite interpolant of the step, θ ∈ [0, 1].
@njit(cache=True, error_model="numpy")
def _switch_fn(c, theta, y0, f0, y1, f1, x0, xd, h, which, j):  # type: ignore[no-untyped-def]
    t2 = theta * theta
    t3 = t2 * theta
    a, b, d, e = 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + theta, -2 * t3 + 3 * t2, t3 - t2
    if which >= 2:
        v = a * y0[Y_V] + b * h * f0[Y_V] + d * y1[Y_V] + e * h * f1[Y_V]
        return v - c[P_VREG] if which == 2 else v + c[P_VREG]
    yi = _hermite(a, b, d, e, h, y0, f0, y1, f1)
    sg = _segments(c, yi, x0, xd * theta * h, xd)
    return sg[2 * j] if which == 0 else sg[2 * j + 1]


@njit(cache=True, error_model="numpy")
def _locate(c, y0, f0, y1, f1, x0, xd, h, which, j):  # type: ignore[no-untyped-def]
    """Bisect the event function's sign change on the step's interpolant; θ of the switch."""
    lo = 0.0
    hi = 1.0
    g_lo = _switch_fn(c, lo, y0, f0, y1, f1, x0, xd, h, which, j)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        g_mid = _switch_fn(c, mid, y0, f0, y1, f1, x0, xd, h, which, j)
        if (g_mid > 0.0) == (g_lo > 0.0):
            lo = mid
            g_lo = g_mid
        else:
            hi = mid
    return hi


@njit(cache=True, error_model="numpy")
def _set_taut(c, y, x, xd):  # type: ignore[no-untyped-def]
    """Each segment's regime from the state: taut iff δ > 0 and its tension law > 0."""
    sg = _segments(c, y, x, 0.0, xd)
    c[S_TAUT1] = 1.0 if sg[0] > 0.0 and sg[1] > 0.0 else 0.0
    c[S_TAUT2] = 1.0 if sg[2] > 0.0 and sg[3] > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def _after_part(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """Update the discrete states at the end of an integrated part (h seconds) of a step."""
    if ON_PI and c[D_NSEG] > 1.5 and c[D_SIGP] > 0.0:  # bearing presliding (elasto-plastic)
        t1, t2 = _tensions(c, _segments(c, y, x, 0.0, xd))
        zmax = _bearing_limit(c, t1, t2)
        c[S_PZ] = min(max(c[S_PZ] + y[Y_S] - c[S_PS0], -zmax), zmax)
        c[S_PS0] = y[Y_S]
    if ON_PJ and c[R_PJ_ON] > 0.0 and c[S_RECSEAT] == 0.0:
        # The weight-side segment carries the seat (one segment: S_TAUT2 is only
        # refreshed at a step's start; S_TAUT1 follows every located switch).
        taut = c[S_TAUT2] if c[D_NSEG] > 1.5 else c[S_TAUT1]
        _reseat(c, taut <= 0.0, c[P_PRELOAD] + x - c[P_PROJ] * y[Y_U], h)


@njit(cache=True, error_model="numpy")
def _reseat(c, slack, elongation, h):  # type: ignore[no-untyped-def]
    """The pulley seat after h seconds more of a slack (or taut) fibre.

    The fibre leaves its groove once its loop is ``onset`` deep and has lain slack for
    ``dwell`` (held by groove friction, it needs time to slide out), and has moved over to
    the next seat within a few depth scales more: with ``seats`` = 0 the other of two
    grooves (it toggles), else one more step up the groove's flank, up to ``seats`` steps
    (the flange), where it stays. The seat follows the episode's deepest geometric slack,
    so it never moves back within one episode; when the fibre is taut again it stays where
    it is. The same law runs on the model's slack (``_after_part``) and on the recorded
    one (``measured_seats``).
    """
    if slack:
        c[S_SLACKT] += h
        c[S_DEPTH] = max(c[S_DEPTH], -(elongation + c[S_LBASE]))
        if c[S_SLACKT] >= c[R_PJ_DWELL]:
            base, step = c[S_LBASE], c[R_PJ_STEP]
            seats = math.floor(c[R_PJ_SEATS] + 0.5)
            if seats < 1 or step == 0.0:
                target = step if abs(base) <= abs(base - step) else 0.0  # the other seat
            else:  # one step further up the flank, at most ``seats`` steps
                target = min(math.floor(base / step + 0.5) + 1.0, seats) * step
            beyond = max(0.0, c[S_DEPTH] - c[R_PJ_ONSET])
            c[S_LOFF] = base + (target - base) * (1.0 - math.exp(-beyond / c[R_PJ_DEPTH]))
    elif c[S_SLACKT] > 0.0:  # the episode is over: the fibre stays in its new seat
        c[S_LBASE] = c[S_LOFF]
        c[S_DEPTH] = 0.0
        c[S_SLACKT] = 0.0


@njit(cache=True, error_model="numpy")
def _step(c, y, x0, xd, h):  # type: ignore[no-untyped-def]
    """Advance y by h, splitting the step at every regime switch ."""
    nseg = 2 if ON_PI and c[D_NSEG] > 1.5 else 1
    remaining = h
    xs = x0
    _set_taut(c, y, xs, xd)  # ẋ, and c·δ̇, step at sample boundaries
    for _ in range(MAX_SWITCH * nseg):
        zone = int(c[S_ZONE])
        yn, f0 = _rk4(c, y, xs, xd, remaining)
        x_end = xs + xd * remaining
        sg = _segments(c, yn, x_end, 0.0, xd)
        zone_end = _zone(yn[Y_V], c)
        theta, first, have_f1 = 2.0, -1, False
        f1 = ZERO
        for j in range(nseg):
            delta_end, force_end = sg[2 * j], sg[2 * j + 1]
            if c[S_TAUT1 + j] > 0.0:
                switch = force_end < 0.0
                which = 1
            else:
                switch = delta_end > 0.0 and force_end > 0.0
                which = 0 if _segments(c, y, xs, 0.0, xd)[2 * j] <= 0.0 else 1
            if switch:
                if not have_f1:
                    f1, have_f1 = _rhs(c, yn, x_end, xd), True
                th = _locate(c, y, f0, yn, f1, xs, xd, remaining, which, j)
                if th < theta:
                    theta, first = th, j
        if first < 0 and zone_end == zone:
            _after_part(c, yn, x_end, xd, remaining)
            return yn
        if zone_end != zone:
            if not have_f1:
                f1 = _rhs(c, yn, x_end, xd)
            # Leaving +1 or entering +1 crosses v = v_reg; otherwise v = −v_reg.
            zone_which = 2 if (zone == 1 or (zone == 0 and zone_end == 1)) else 3
            th = _locate(c, y, f0, yn, f1, xs, xd, remaining, zone_which, nseg)  # j unused
            if th < theta:
                theta, first = th, -1
        part = theta * remaining
        y, _ = _rk4(c, y, xs, xd, part)
        xs = xs + xd * part
        _after_part(c, y, xs, xd, part)
        remaining = remaining - part
        if first >= 0:
            c[S_TAUT1 + first] = 0.0 if c[S_TAUT1 + first] > 0.0 else 1.0
        else:
            c[S_ZONE] = zone + 1 if zone_end > zone else zone - 1
        if remaining <= 1e-15:
            return y
    y, _ = _rk4(c, y, xs, xd, remaining)
    x_end = xs + xd * remaining
    _set_taut(c, y, x_end, xd)
    c[S_ZONE] = _zone(y[Y_V], c)
    _after_part(c, y, x_end, xd, remaining)
    return y


@njit(cache=True, error_model="numpy")
def _substeps(c, y, x, xd, dt, base):  # type: ignore[no-untyped-def]
    """Steps for the next interval: |λ|·h ≤ 0.5 for oscillations, ≤ 1.5 for decays.

    RK4 where it needs no more than the exponential step (``_etdrk4``), for which the two
    stiffest decays, the rim's velocity and the LuGre bristle's relaxation, do not count
    (c[E_ON] says which this interval takes).
    """
    c[E_ON] = 0.0
    if not ON_ANY or c[D_DYN] <= 0.0:
        return base
    sg = _segments(c, y, x, 0.0, xd)
    t_est = 1.5 * max(sg[1], sg[3], 0.0) + c[D_T0]
    osc, osc_exp, real = c[D_OSC], c[E_OSC], c[D_REAL]
    strings = abs(y[Y_A1]) + abs(y[Y_AD1]) + abs(y[Y_A2]) + abs(y[Y_AD2]) + abs(c[D_F1] + c[D_F2])
    if c[R_TV_ON] > 0.0 and strings > 0.0:  # an unexcited string mode stays exactly zero
        modes = math.sqrt(max(c[D_W1], c[D_W2]) * t_est) + c[D_CM1] + c[D_CM2]
        osc, osc_exp = max(osc, modes), max(osc_exp, modes)
    if c[R_SL_ON] > 0.0:
        real = max(real, c[D_SL] * t_est / (c[P_VREG] * c[P_MASS]))
    real_exp = real
    real = max(real, c[E_RIM])
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
    n = max(base, math.ceil(dt * osc / 0.5), math.ceil(dt * real / 1.5))
    n_exp = max(base, math.ceil(dt * osc_exp / 0.5), math.ceil(dt * real_exp / 1.5))
    if EXP_COST * n_exp < n:
        c[E_ON] = 1.0
        n = n_exp
    return min(n, NSUB_MAX)


@njit(cache=True, error_model="numpy")
def _sample_out(c, y, x, xd, i, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    sg = _segments(c, y, x, 0.0, xd)
    out_u[i] = y[Y_U]
    out_v[i] = y[Y_V]
    t1 = sg[1] if c[S_TAUT1] > 0.0 else 0.0
    out_t1[i] = t1 if t1 > 0.0 else 0.0
    t2 = t1
    if ON_PI and c[D_NSEG] > 1.5:
        t2 = sg[3] if c[S_TAUT2] > 0.0 else 0.0
    out_t2[i] = t2 if t2 > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def advance_into(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    """Integrate from the state (array of NY; discrete part in c) at x[0] over x[1:].

    Writes u, v and the drive- and weight-side tensions after each sample into
    out_*[i + 1] and the final state back into ``state`` and c, so a run can go on block
    by block. Returns the largest number of substeps one interval took.
    """
    return _advance(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2, np.empty(0))


@njit(cache=True, error_model="numpy")
def _advance(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2, seat):  # type: ignore[no-untyped-def]
    """``advance_into``; with ``seat`` (one per sample of x) the pulley seat's offset.

    A seat given is the one the *recorded* slack episodes put the fibre in
    (``measured_seats`` at every sample): over the interval after sample i the seat is
    seat[i + 1], the episodes up to sample i read. Without, the seat follows the model's
    own slack (``_after_part``).
    """
    y = _tuple_of(state)
    c[S_ZONE] = _zone(y[Y_V], c)
    recorded = ON_PJ and seat.shape[0] >= x.shape[0] and c[R_PJ_ON] > 0.0
    c[S_RECSEAT] = 1.0 if recorded else 0.0
    most = 0
    for i in range(x.shape[0] - 1):
        xd = (x[i + 1] - x[i]) / dt
        if recorded:
            c[S_LOFF] = seat[i + 1]
        nsub = _substeps(c, y, x[i], xd, dt, substeps)
        most = max(most, nsub)
        h = dt / nsub
        for j in range(nsub):
            y = _step(c, y, x[i] + xd * j * h, xd, h)
        _sample_out(c, y, x[i + 1], xd, i + 1, out_u, out_v, out_t1, out_t2)
    for k in range(NY):
        state[k] = y[k]
    c[S_RECSEAT] = 0.0
    return most


@njit(cache=True, error_model="numpy")
def simulate_into(x, dt, substeps, row, knots, coef, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    """Integrate one parameter row from static rest over the drive samples x (relative)."""
    return _from_rest(x, dt, substeps, row, knots, coef, out_u, out_v, out_t1, out_t2, np.empty(0))


@njit(cache=True, error_model="numpy")
def _from_rest(x, dt, substeps, row, knots, coef, out_u, out_v, out_t1, out_t2, seat):  # type: ignore[no-untyped-def]
    """``simulate_into``, the seat given as in ``_advance``."""
    c = pack(row, knots, coef)
    y = rest_state(c)
    out_u[0] = y[Y_U]
    out_v[0] = y[Y_V]
    out_t1[0] = c[D_K1] * (c[D_D10] + x[0])  # unclamped, no rate term (as always)
    out_t2[0] = out_t1[0] if c[D_NSEG] < 1.5 else c[D_K2] * c[D_D20]
    state = np.empty(NY)
    for k in range(NY):
        state[k] = y[k]
    return _advance(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2, seat)


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_batch_into(x, dt, substeps, rows, knots, coef, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    """simulate_into for each row (and row of x, unless x has one row), in parallel."""
    for b in prange(rows.shape[0]):
        xb = x[b] if x.shape[0] > 1 else x[0]
        simulate_into(
            xb, dt, substeps, rows[b], knots, coef, out_u[b], out_v[b], out_t1[b], out_t2[b]
        )


@njit(cache=True, error_model="numpy")
def measured_seats(row, x, u, force, dt, slack_n, starts):  # type: ignore[no-untyped-def]
    """The pulley seat (I_LOFF … I_SLACKT) at each start, from the recorded episodes.

    ``_reseat``'s law driven by the recorded slack (force below ``slack_n``) and the
    recorded geometry (x relative to rest, u on the model's scale), from the seat at
    rest. Which groove the fibre sits in is not observable at a restart, but every slack
    episode that moved it is in the recording; a simulated seat, carried from segment to
    segment, follows the *model's* slack episodes instead, and one episode too short
    or too long in a chaotic bounce puts every later seat in the wrong groove.
    """
    c = np.zeros(C_TABLE)
    for i in range(N_ROW):
        c[i] = row[i]
    out = np.zeros((starts.shape[0], 4))
    k = 0
    for j in range(starts.shape[0]):
        while k < starts[j]:
            _reseat(c, force[k] < slack_n, c[P_PRELOAD] + x[k] - c[P_PROJ] * u[k], dt)
            k += 1
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = c[S_LOFF], c[S_LBASE], c[S_DEPTH], c[S_SLACKT]
    return out


@njit(cache=True, error_model="numpy")
def measured_state(c, x, xd, m):  # type: ignore[no-untyped-def]
    """A full state from a measured start m (columns I_*) at drive x (m), rate xd (m/s).

    Measured: weight u (m), v (m/s) and the drive-side force F (N). The effects' own
    states are not measured and take quasi-static values: pulley rim where the drive-side
    segment carries the measured F (taut) or both segments equal tension (slack), moving
    with the fibre, bearing presliding holding the tension difference (within its limit);
    Maxwell branches at k₂·hp, hp the elongation high-passed with τ (the branch's response
    to the measured history, computed by the caller); string modes at their static sag
    for the measured tension (rest sag while slack; ``simulate_chained_into`` replaces
    them by the previous segment's); LuGre bristle holding the measured
    force balance n·F − m·g·sin α, limited to (and, faster than v_s, at) its sliding
    value; pulley-jump seat from the recorded slack episodes (``measured_seats``, in
    m's I_LOFF … I_SLACKT; a seat estimated from the measured elongation at the start,
    rounded to one of the two grooves, picked the wrong groove often enough to cost 340×
    the open-loop error on a clean recording).
    Sets the discrete state in c; returns the continuous state tuple.
    """
    u, v, force = m[I_U], m[I_V], m[I_F]
    n = c[P_PROJ]
    taut = force > 0.25 * c[D_T0]
    s, sd = 0.0, 0.0
    if ON_PI and c[D_NSEG] > 1.5:
        k1, k2 = c[D_K1], c[D_K2]
        sd = (k1 * xd + k2 * n * v) / (k1 + k2)
        if taut:
            s = c[D_D10] + x - (force - c[D_C1] * (xd - sd)) / k1
        else:
            s = (k1 * (c[D_D10] + x) - k2 * (c[D_D20] - n * u)) / (k1 + k2)
    a1, a2 = 0.0, 0.0
    if ON_TV and c[R_TV_ON] > 0.0:
        scale = c[D_T0] / force if taut else 1.0
        a1, a2 = c[D_AR1] * scale, c[D_AR2] * scale
    z = 0.0
    if ON_SS and c[D_SS_ON] > 0.0:
        g = c[P_FRICTION_N] * _mu(abs(v), c) * (1.0 + c[R_SS_RATIO] * _stribeck(v, c))
        limit = g / c[D_SIG0]
        if abs(v) > c[R_SS_VS]:
            z = limit if v > 0.0 else -limit
        else:
            z = min(max((n * max(force, 0.0) - c[P_GRAVITY_N]) / c[D_SIG0], -limit), limit)
    q1, q2 = c[D_KB1] * m[I_HP], c[D_KB2] * m[I_HP]
    y = _state(u, v, s, sd, q1, q2, a1, 0.0, a2, 0.0, z)
    c[S_LOFF], c[S_LBASE], c[S_DEPTH], c[S_SLACKT] = m[I_LOFF], m[I_LBASE], m[I_DEPTH], m[I_SLACKT]
    c[S_PZ], c[S_PS0] = 0.0, s
    if ON_PI and c[D_NSEG] > 1.5 and c[D_SIGP] > 0.0:
        _set_taut(c, y, x, xd)
        t1, t2 = _tensions(c, _segments(c, y, x, 0.0, xd))
        zmax = _bearing_limit(c, t1, t2)
        c[S_PZ] = min(max((t1 - t2) / c[D_SIGP], -zmax), zmax)
    return y


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_chained_into(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats
):
    """``simulate_segments_into`` segment after segment per row (parallel over rows only).

    The string modes and the LuGre bristle are not observable from the gauges at a start
    (a ringing span's phase; the bristle's pre-sliding while sticking), but they are
    driven by the tension and the weight's motion: simulating them is their observer. So
    every segment after the first starts them where the previous segment's run had them
    at that sample; everything else starts from ``measured_state`` as before (the pulley
    seat from the recorded slack episodes, ``measured_seats``).
    """
    for b in prange(rows.shape[0]):
        _chain_into(b, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats)


@njit(cache=True, nogil=True, error_model="numpy")
def simulate_chained_serial(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats
):
    """``simulate_chained_into`` on the calling thread, without the GIL (traces side by side)."""
    for b in range(rows.shape[0]):
        _chain_into(b, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats)


@njit(cache=True, error_model="numpy")
def _chain_into(  # type: ignore[no-untyped-def]
    b, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats
):
    """Row b of ``simulate_chained_into``: its segments one after the other."""
    segs = starts.shape[0]
    carried = np.zeros(NCARRY)
    have = False
    for s in range(segs):
        n = lens[s]
        xs = x[starts[s] : starts[s] + n]
        ou, ot = out_u[b, s], out_t1[b, s]
        seat = seats[b, starts[s] : starts[s] + n]  # empty: the model's own slack
        sv, st2 = np.empty(n), np.empty(n)
        c = pack(rows[b], knots, coef)
        xd = (xs[1] - xs[0]) / dt if n > 1 else 0.0
        if starts[s] == 0:
            y = rest_state(c)
            ou[0], sv[0] = y[Y_U], y[Y_V]
            ot[0] = c[D_K1] * (c[D_D10] + xs[0])
            st2[0] = ot[0]
        else:
            y = measured_state(c, xs[0], xd, init[b, s])
            if have:
                y = _with_carried(y, carried)
            _set_taut(c, y, xs[0], xd)
            _sample_out(c, y, xs[0], xd, 0, ou, sv, ot, st2)
        state = np.empty(NY)
        for k in range(NY):
            state[k] = y[k]
        hand = starts[s + 1] - starts[s] if s + 1 < segs else n
        if 0 < hand < n:
            h1 = hand + 1
            _advance(
                xs[:h1], dt, substeps, c, state, ou[:h1], sv[:h1], ot[:h1], st2[:h1], seat[:h1]
            )
            _carry_out(state, carried)
            have = True
            tail = slice(hand, n)
            _advance(
                xs[tail], dt, substeps, c, state, ou[tail], sv[tail], ot[tail], st2[tail],
                seat[tail],
            )  # fmt: skip
        elif n > 1:
            _advance(xs, dt, substeps, c, state, ou, sv, ot, st2, seat)
        for i in range(n, ou.shape[0]):
            ou[i] = ou[n - 1]
            ot[i] = ot[n - 1]


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_segments_into(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats
):
    """Many short runs (segments) of many rows, in parallel over (set, segment).

    Segment s covers samples starts[s] … starts[s] + lens[s] − 1 of the relative drive
    x. A segment at sample 0 starts from static rest (as ``simulate_into``); any other
    from ``measured_state`` of init[b, s] (columns I_*). Writes u and the drive-side
    tension into out_*[b, s, :lens[s]], the last value held to the end of the row.
    seats[b] (one per sample of x, or none): the pulley seat the runs hold (``_advance``).
    """
    segs = starts.shape[0]
    for flat in prange(rows.shape[0] * segs):
        _segment_into(
            flat // segs, flat % segs, x, dt, substeps, rows, knots, coef, starts, lens, init,
            out_u, out_t1, seats,
        )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def simulate_segments_serial(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats
):
    """``simulate_segments_into`` on the calling thread, without the GIL (traces side by side)."""
    segs = starts.shape[0]
    for flat in range(rows.shape[0] * segs):
        _segment_into(
            flat // segs, flat % segs, x, dt, substeps, rows, knots, coef, starts, lens, init,
            out_u, out_t1, seats,
        )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _segment_into(  # type: ignore[no-untyped-def]
    b, s, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, seats
):
    """Segment s of row b of ``simulate_segments_into``."""
    n = lens[s]
    xs = x[starts[s] : starts[s] + n]
    ou = out_u[b, s]
    ot = out_t1[b, s]
    seat = seats[b, starts[s] : starts[s] + n]  # empty: the model's own slack
    sv, st2 = np.empty(n), np.empty(n)
    if starts[s] == 0:
        _from_rest(xs, dt, substeps, rows[b], knots, coef, ou, sv, ot, st2, seat)
    else:
        c = pack(rows[b], knots, coef)
        xd = (xs[1] - xs[0]) / dt if n > 1 else 0.0
        y = measured_state(c, xs[0], xd, init[b, s])
        _set_taut(c, y, xs[0], xd)
        _sample_out(c, y, xs[0], xd, 0, ou, sv, ot, st2)
        state = np.empty(NY)
        for k in range(NY):
            state[k] = y[k]
        if n > 1:
            _advance(xs, dt, substeps, c, state, ou, sv, ot, st2, seat)
    for i in range(n, ou.shape[0]):
        ou[i] = ou[n - 1]
        ot[i] = ot[n - 1]
