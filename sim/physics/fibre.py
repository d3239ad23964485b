"""The fibre, the weight and the built-in terms: constants, forces and right-hand side.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` writes
``kernel.py`` (the head: layout and state helpers) and the parts ``fibre``,
``integrator`` and ``runners`` into one module for a set of terms. Its imports are for
reading and linting only.
"""

from __future__ import annotations

# <imports>
import math

import numpy as np
from numba import njit

from sim.physics.kernel import (
    ON_PI,
    ON_SS,
    ON_TV,
    ON_VE,
    ON_X,
    ZERO,
    _state,
    _terms_after_part,
    _terms_extension,
    _terms_friction,
    _terms_on,
    _terms_pack,
    _terms_zoned,
)
from sim.physics.layout import *

# </imports>


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
    _terms_pack(c)
    c[D_OSC], c[D_REAL] = osc, real
    on = c[R_VE_ON] + c[R_TV_ON] + c[R_PI_ON] + c[R_SS_ON] + c[R_X_ON] + _terms_on(c)
    c[D_DYN] = 1.0 if on > 0.0 else 0.0
    table = c[P_FRICTION_N] != 0.0 and c[D_SS_ON] == 0.0
    c[D_ZONES] = 1.0 if table or _terms_zoned(c) else 0.0
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
    ext1, rate1, ext2, rate2 = _terms_extension(c, y, ext1, rate1, ext2, rate2)
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
    fric = _terms_friction(c, v, zone, t2, fric)
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
    _terms_after_part(c, y, x, xd, h)


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
