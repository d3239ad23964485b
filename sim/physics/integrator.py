"""One integrator: RK4 or ETDRK4 steps split at located events, and the substep count.

A part of the compiled model's text, never run as itself (``kernel.py`` says how it is
composed). It advances the state by the right-hand side ``fibre._rhs``; the events are
each fibre segment's taut/slack switch and the friction branch's, located on the step's
cubic Hermite interpolant.
"""

from __future__ import annotations

# <imports>
import math

from numba import njit

from sim.physics.fibre import _after_part, _rhs, _segments, _set_taut, _zone
from sim.physics.kernel import (
    EXP_COST,
    MAX_SWITCH,
    NSUB_MAX,
    ON_ANY,
    SEGMENTS,
    ZERO,
    _axpy,
    _combine,
    _hermite,
    _stiff_set,
    _terms_decay,
    _terms_substeps,
)
from sim.physics.layout import *

# </imports>


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
    return rim, _terms_decay(c, v, 0.0)


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
def _step(c, y, x0, xd, h):  # type: ignore[no-untyped-def]
    """Advance y by h, splitting the step at every regime switch ."""
    nseg = 2 if SEGMENTS > 1 and c[D_NSEG] > 1.5 else 1
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
    real_exp = real
    # The terms' rates in this interval (maxima, in any order; see each term's hook).
    # <splice substeps>
    osc, osc_exp, real, real_exp = _terms_substeps(c, y, dt, t_est, osc, osc_exp, real, real_exp)
    # </splice substeps>
    n = max(base, math.ceil(dt * osc / 0.5), math.ceil(dt * real / 1.5))
    n_exp = max(base, math.ceil(dt * osc_exp / 0.5), math.ceil(dt * real_exp / 1.5))
    if EXP_COST * n_exp < n:
        c[E_ON] = 1.0
        n = n_exp
    return min(n, NSUB_MAX)
