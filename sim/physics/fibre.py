"""The fibre (one segment or two), the weight, the friction: constants, forces, rates.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` writes
``kernel.py`` (the head: layout, state helpers, hook calls), the parts ``fibre``,
``integrator`` and ``runners`` and the composed terms into one module for a set of terms;
the ``# <splice HOOK>`` sites get the terms' bodies. Its imports are for reading and
linting only.
"""

from __future__ import annotations

# <imports>
import numpy as np
from numba import njit

from sim.physics.kernel import (
    ON_X,
    SEGMENTS,
    _terms_after_part,
    _terms_branch,
    _terms_extension,
    _terms_friction,
    _terms_friction_law,
    _terms_on,
    _terms_pack,
    _terms_rates,
    _terms_replaces_friction,
    _terms_rest,
    _terms_segments,
    _terms_settle,
    _terms_weight,
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
    t0 = c[P_GRAVITY_N] / c[P_PROJ]  # one segment unless a term splits the fibre
    c[D_T0] = t0
    c[D_NSEG] = 1.0
    c[D_K1], c[D_C1], c[D_K2], c[D_C2] = k, damp, k, damp
    c[D_D10], c[D_D20] = c[P_PRELOAD], c[P_PRELOAD]
    # The terms' constants, and the oscillations (for RK4, and what the exponential
    # step leaves) and decays they bring, 1/s: maxima, in any order.
    osc, osc_exp, real = _terms_pack(c, 0.0, 0.0, 0.0)
    c[E_OSC] = osc_exp
    c[D_OSC], c[D_REAL] = osc, real
    on = c[R_X_ON] + _terms_on(c)
    c[D_DYN] = 1.0 if on > 0.0 else 0.0
    table = c[P_FRICTION_N] != 0.0 and not _terms_replaces_friction(c)
    c[D_ZONES] = 1.0 if table or _terms_zoned(c) else 0.0
    c[S_TAUT1], c[S_TAUT2] = 1.0, 1.0
    c[E_H] = -1.0  # no rim weights yet
    return c


@njit(cache=True, error_model="numpy")
def rest_state(c):  # type: ignore[no-untyped-def]
    """Static rest: weight and pulley still, fibre taut at T₀, strings at their gravity sag."""
    return _terms_rest(c)


@njit(cache=True, error_model="numpy")
def _segments(c, y, xa, xb, xd):  # type: ignore[no-untyped-def]
    """(δ₁, F₁, δ₂, F₂, δ̇₁, δ̇₂): each segment's elongation and tension law at x = xa + xb."""
    n = c[P_PROJ]
    # What the terms add to each segment's length and rate, and to its tension law (+ 0.0
    # without: the union's sums, bit for bit).
    ext1, rate1, ext2, rate2, q1, q2 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    # <splice extension>
    ext1, rate1, ext2, rate2 = _terms_extension(c, y, ext1, rate1, ext2, rate2)
    # </splice extension>
    # <splice branch>
    q1, q2 = _terms_branch(c, y, q1, q2)
    # </splice branch>
    if SEGMENTS < 2 or c[D_NSEG] < 1.5:  # one segment (returning here is 1.8× faster)
        d = c[D_D10] + xa + xb - n * y[Y_U] + (ext1 + ext2)
        dd = xd - n * y[Y_V] + (rate1 + rate2)
        f = c[D_K1] * d + c[D_C1] * dd + q1
        return d, f, d, f, dd, dd
    # Two: the term that splits the fibre (the pulley's rim between them) gives them.
    d1, f1, d2, f2, dd1, dd2 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    # <splice segments>
    d1, f1, d2, f2, dd1, dd2 = _terms_segments(
        c, y, xa, xb, xd, n, ext1, rate1, ext2, rate2, q1, q2, d1, f1, d2, f2, dd1, dd2
    )
    # </splice segments>
    return d1, f1, d2, f2, dd1, dd2


@njit(cache=True, error_model="numpy")
def _tensions(c, sg):  # type: ignore[no-untyped-def]
    t1 = sg[1] if c[S_TAUT1] > 0.0 else 0.0
    if SEGMENTS < 2 or c[D_NSEG] < 1.5:
        return t1, t1
    return t1, (sg[3] if c[S_TAUT2] > 0.0 else 0.0)


# <added-force>: ``sim.physics.compose`` replaces this function in a composed kernel by
# the sum of the added effects' forces; in this file no effect is added.
@njit(cache=True, error_model="numpy")
def _added_force(c, y, t2):  # type: ignore[no-untyped-def]
    """Force on the weight (N, up the incline) of the effects added outside this file."""
    return 0.0


# </added-force>


@njit(cache=True, error_model="numpy")
def _rhs(c, y, xa, xd):  # type: ignore[no-untyped-def]
    """dy/dt at drive position xa (rate xd) in the current regimes."""
    sg = _segments(c, y, xa, 0.0, xd)
    t1, t2 = _tensions(c, sg)
    v = y[Y_V]
    zone = int(c[S_ZONE])
    # A term may replace the table's friction law (and bring its own state's rate).
    replaced, fric, zd = False, 0.0, 0.0
    # <splice friction_law>
    replaced, fric, zd = _terms_friction_law(c, y, v, replaced, fric, zd)
    # </splice friction_law>
    if not replaced:
        fric = _friction(v, zone, c)
    # <splice friction>
    fric = _terms_friction(c, v, zone, t2, fric)
    # </splice friction>
    drive = -c[P_GRAVITY_N] - fric
    drive += c[P_PROJ] * t2  # + 0.0 while slack: the baseline's sum, bit for bit
    if ON_X and c[R_X_ON] > 0.0:
        drive += _added_force(c, y, t2)
    # A term's own force on the weight (an added effect's, reading its states).
    # <splice weight>
    drive = _terms_weight(c, y, v, t2, drive)
    # </splice weight>
    acc = drive / c[P_MASS]
    # <splice rates>
    return _terms_rates(c, y, sg, t1, t2, zd, v, acc)  # with the terms' rates
    # </splice rates>


@njit(cache=True, error_model="numpy")
def _set_taut(c, y, x, xd):  # type: ignore[no-untyped-def]
    """Each segment's regime from the state: taut iff δ > 0 and its tension law > 0."""
    sg = _segments(c, y, x, 0.0, xd)
    c[S_TAUT1] = 1.0 if sg[0] > 0.0 and sg[1] > 0.0 else 0.0
    c[S_TAUT2] = 1.0 if sg[2] > 0.0 and sg[3] > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def _after_part(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """Update the discrete states at the end of an integrated part (h seconds) of a step."""
    # <splice settle>
    _terms_settle(c, y, x, xd, h)
    # </splice settle>
    # <splice after_part>
    _terms_after_part(c, y, x, xd, h)
    # </splice after_part>


@njit(cache=True, error_model="numpy")
def _sample_out(c, y, x, xd, i, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    sg = _segments(c, y, x, 0.0, xd)
    out_u[i] = y[Y_U]
    out_v[i] = y[Y_V]
    t1 = sg[1] if c[S_TAUT1] > 0.0 else 0.0
    out_t1[i] = t1 if t1 > 0.0 else 0.0
    t2 = t1
    if SEGMENTS > 1 and c[D_NSEG] > 1.5:
        t2 = sg[3] if c[S_TAUT2] > 0.0 else 0.0
    out_t2[i] = t2 if t2 > 0.0 else 0.0
