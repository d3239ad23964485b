"""The baseline model's compiled integrator (STAND.md §2).

State (u, v): weight displacement up the incline and its velocity. The drive position x
is given at the sample times and is linear inside each sample interval, so every RK4
step sees a smooth right-hand side. The fibre is either *taut* (T = k·δ + c·δ̇) or
*slack* (T = 0); the switch is an event located inside the step:

* taut → slack when k·δ + c·δ̇ falls through 0 (T is continuous there);
* slack → taut when δ rises through 0 (T jumps by c·δ̇), or when δ > 0 and k·δ + c·δ̇
  rises through 0.

The friction law has branches too: sliding up (v ≥ v_reg), sliding down (v ≤ −v_reg)
and the linear regularisation band between. At the top of a free flight the weight
crosses the band (2 mm/s wide) in a fraction of a step, so a step that straddled it would
see friction flip sign inside one RK4 step: a first-order error that decides when the
next snatch happens. The branch is therefore also held fixed within a step and switched
at located crossings of v = ±v_reg.

The step is split at the located crossing and each part is integrated with its own
right-hand side, so neither the jump nor the kinks cost the method its order. Crossings
are found on the cubic Hermite interpolant of the step (fourth order, like the step).

Parameter vector layout (one row per parameter set) is given by the P_* indices.

Speed: the small right-hand-side functions are inlined at numba's IR level
(``inline="always"``): calls that pass arrays are otherwise not inlined and pay for
reference counting on every call — 2.7× slower (measured: 68 → 25 ms for a 60 s run).
The price is a longer first compile (≈ 12 s, cached in __pycache__ afterwards).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

P_MASS, P_PROJ, P_STIFF, P_DAMP, P_FRICTION_N, P_GRAVITY_N, P_PRELOAD, P_VREG = range(8)
N_PARAMS = 8


@njit(cache=True, error_model="numpy", inline="always")
def _mu(speed, knots, coef):  # type: ignore[no-untyped-def]
    """μ(speed) from the PCHIP pieces; the end pieces extend smoothly past the first knot."""
    n = knots.shape[0]
    if speed >= knots[n - 1]:
        s = knots[n - 1] - knots[n - 2]
        i = n - 2
        return ((coef[0, i] * s + coef[1, i]) * s + coef[2, i]) * s + coef[3, i]
    i = 0
    while i < n - 2 and speed > knots[i + 1]:
        i += 1
    s = speed - knots[i]
    return ((coef[0, i] * s + coef[1, i]) * s + coef[2, i]) * s + coef[3, i]


@njit(cache=True, error_model="numpy", inline="always")
def _zone(v, p):  # type: ignore[no-untyped-def]
    """Friction branch: +1 sliding up, -1 sliding down, 0 inside the regularisation band."""
    if p[P_FRICTION_N] == 0.0:
        return 0
    if v >= p[P_VREG]:
        return 1
    if v <= -p[P_VREG]:
        return -1
    return 0


@njit(cache=True, error_model="numpy", inline="always")
def _friction(v, zone, p, knots, coef):  # type: ignore[no-untyped-def]
    # The branch is fixed for the whole step (an RK stage may stray just past v_reg): each
    # branch is smooth, and the switch between branches is an event like the slack one.
    fn = p[P_FRICTION_N]
    if fn == 0.0:
        return 0.0
    if zone > 0:
        return fn * _mu(v, knots, coef)
    if zone < 0:
        return -fn * _mu(-v, knots, coef)
    vreg = p[P_VREG]
    return fn * _mu(vreg, knots, coef) * v / vreg


@njit(cache=True, error_model="numpy", inline="always")
def _accel(u, v, x, xd, taut, zone, p, knots, coef):  # type: ignore[no-untyped-def]
    drive = -p[P_GRAVITY_N] - _friction(v, zone, p, knots, coef)
    if taut:
        n = p[P_PROJ]
        tension = p[P_STIFF] * (p[P_PRELOAD] + x - n * u) + p[P_DAMP] * (xd - n * v)
        drive += n * tension
    return drive / p[P_MASS]


@njit(cache=True, error_model="numpy")
def _rk4(u, v, x0, xd, h, taut, zone, p, knots, coef):  # type: ignore[no-untyped-def]
    a1 = _accel(u, v, x0, xd, taut, zone, p, knots, coef)
    u2 = u + 0.5 * h * v
    v2 = v + 0.5 * h * a1
    xm = x0 + 0.5 * h * xd
    a2 = _accel(u2, v2, xm, xd, taut, zone, p, knots, coef)
    u3 = u + 0.5 * h * v2
    v3 = v + 0.5 * h * a2
    a3 = _accel(u3, v3, xm, xd, taut, zone, p, knots, coef)
    u4 = u + h * v3
    v4 = v + h * a3
    a4 = _accel(u4, v4, x0 + h * xd, xd, taut, zone, p, knots, coef)
    un = u + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
    vn = v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return un, vn, a1


# Event functions: which = 0 → δ, 1 → k·δ + c·δ̇, 2 → v − v_reg, 3 → v + v_reg.
@njit(cache=True, error_model="numpy")
def _switch_fn(theta, u0, v0, a0, u1, v1, a1, x0, xd, h, which, p):  # type: ignore[no-untyped-def]
    # Cubic Hermite interpolants of u and v over the step, θ ∈ [0, 1].
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2 * t3 - 3 * t2 + 1
    h10 = t3 - 2 * t2 + theta
    h01 = -2 * t3 + 3 * t2
    h11 = t3 - t2
    v = h00 * v0 + h10 * h * a0 + h01 * v1 + h11 * h * a1
    if which == 2:
        return v - p[P_VREG]
    if which == 3:
        return v + p[P_VREG]
    u = h00 * u0 + h10 * h * v0 + h01 * u1 + h11 * h * v1
    n = p[P_PROJ]
    delta = p[P_PRELOAD] + x0 + xd * theta * h - n * u
    if which == 0:
        return delta
    return p[P_STIFF] * delta + p[P_DAMP] * (xd - n * v)


@njit(cache=True, error_model="numpy")
def _locate(u0, v0, a0, u1, v1, a1, x0, xd, h, which, p):  # type: ignore[no-untyped-def]
    """Bisect the event function's sign change on the step's interpolant; θ of the switch."""
    lo = 0.0
    hi = 1.0
    g_lo = _switch_fn(lo, u0, v0, a0, u1, v1, a1, x0, xd, h, which, p)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        g_mid = _switch_fn(mid, u0, v0, a0, u1, v1, a1, x0, xd, h, which, p)
        if (g_mid > 0.0) == (g_lo > 0.0):
            lo = mid
            g_lo = g_mid
        else:
            hi = mid
    return hi


@njit(cache=True, error_model="numpy")
def _taut_now(u, v, x, xd, p):  # type: ignore[no-untyped-def]
    n = p[P_PROJ]
    delta = p[P_PRELOAD] + x - n * u
    return delta > 0.0 and p[P_STIFF] * delta + p[P_DAMP] * (xd - n * v) > 0.0


@njit(cache=True, error_model="numpy")
def _step(u, v, taut, zone, x0, xd, h, p, knots, coef):  # type: ignore[no-untyped-def]
    """Advance one step of length h, splitting it at every regime switch."""
    remaining = h
    xs = x0
    n = p[P_PROJ]
    # ẋ steps at every sample boundary (x is piecewise linear), and so does c·δ̇: the
    # fibre may switch right at the step's start, before any event could be located.
    taut = _taut_now(u, v, xs, xd, p)
    for _ in range(8):  # more switches inside one sub-millisecond step are not physical
        un, vn, a0 = _rk4(u, v, xs, xd, remaining, taut, zone, p, knots, coef)
        x_end = xs + xd * remaining
        delta_end = p[P_PRELOAD] + x_end - n * un
        force_end = p[P_STIFF] * delta_end + p[P_DAMP] * (xd - n * vn)
        if taut:
            fibre_switch = force_end < 0.0
            fibre_which = 1
        else:
            fibre_switch = delta_end > 0.0 and force_end > 0.0
            fibre_which = 0 if p[P_PRELOAD] + xs - n * u <= 0.0 else 1
        zone_end = _zone(vn, p)
        if not fibre_switch and zone_end == zone:
            return un, vn, taut, zone
        a1 = _accel(un, vn, x_end, xd, taut, zone, p, knots, coef)
        theta = 2.0
        if fibre_switch:
            theta = _locate(u, v, a0, un, vn, a1, xs, xd, remaining, fibre_which, p)
        if zone_end != zone:
            # Leaving +1 or entering +1 crosses v = v_reg; otherwise v = −v_reg.
            zone_which = 2 if (zone == 1 or (zone == 0 and zone_end == 1)) else 3
            theta_zone = _locate(u, v, a0, un, vn, a1, xs, xd, remaining, zone_which, p)
            if theta_zone < theta:
                theta = theta_zone
                fibre_switch = False
        part = theta * remaining
        u, v, _ = _rk4(u, v, xs, xd, part, taut, zone, p, knots, coef)
        xs = xs + xd * part
        remaining = remaining - part
        if fibre_switch:
            taut = not taut
        else:
            zone = zone + 1 if (zone_end > zone) else zone - 1
        if remaining <= 1e-15:
            return u, v, taut, zone
    un, vn, _ = _rk4(u, v, xs, xd, remaining, taut, zone, p, knots, coef)
    return un, vn, _taut_now(un, vn, xs + xd * remaining, xd, p), _zone(vn, p)


@njit(cache=True, error_model="numpy")
def advance_into(x, dt, substeps, p, knots, coef, u, v, taut, out_u, out_v, out_t):  # type: ignore[no-untyped-def]
    """Integrate from state (u, v, taut) at x[0] over the samples x[1:], in place.

    Writes the state after each sample into out_*[i + 1] and returns the final state, so
    a long run can be advanced block by block (the simulated stand does). Time is i·dt,
    never summed.
    """
    n = p[P_PROJ]
    h = dt / substeps
    zone = _zone(v, p)
    for i in range(x.shape[0] - 1):
        xd = (x[i + 1] - x[i]) / dt
        for j in range(substeps):
            u, v, taut, zone = _step(u, v, taut, zone, x[i] + xd * j * h, xd, h, p, knots, coef)
        out_u[i + 1] = u
        out_v[i + 1] = v
        if taut:
            t = p[P_STIFF] * (p[P_PRELOAD] + x[i + 1] - n * u) + p[P_DAMP] * (xd - n * v)
            out_t[i + 1] = t if t > 0.0 else 0.0
        else:
            out_t[i + 1] = 0.0
    return u, v, taut


@njit(cache=True, error_model="numpy")
def simulate_into(x, dt, substeps, p, knots, coef, out_u, out_v, out_t):  # type: ignore[no-untyped-def]
    """Integrate one parameter set over the drive samples x (relative to rest), in place.

    Starts at static rest (u = 0, v = 0, taut with δ = δ₀).
    """
    out_u[0] = 0.0
    out_v[0] = 0.0
    out_t[0] = p[P_STIFF] * (p[P_PRELOAD] + x[0])
    advance_into(x, dt, substeps, p, knots, coef, 0.0, 0.0, True, out_u, out_v, out_t)


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_batch_into(x, dt, substeps, params, knots, coef, out_u, out_v, out_t):  # type: ignore[no-untyped-def]
    """simulate_into for each row of params (and of x, unless x has one row), in parallel."""
    for b in prange(params.shape[0]):
        xb = x[b] if x.shape[0] > 1 else x[0]
        simulate_into(xb, dt, substeps, params[b], knots, coef, out_u[b], out_v[b], out_t[b])


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_segments_into(x, dt, substeps, params, knots, coef, starts, lens, init, out_u, out_t):  # type: ignore[no-untyped-def]
    """Many short runs (segments) of many parameter sets, in parallel over (set, segment).

    Segment s covers the samples starts[s] … starts[s] + lens[s] − 1 of the relative
    drive x; a segment at sample 0 starts from static rest (as ``simulate_into``), any
    other for set b from the state init[b, s] = (u, v) (the taut flag follows from the
    state, as in every step). Writes u and T into out_*[b, s, :lens[s]] and
    holds the last value to the end of the row (so a measurement transform over the
    padded row sees the run "held beyond its end").
    """
    segs = starts.shape[0]
    for flat in prange(params.shape[0] * segs):
        _segment_into(
            flat // segs, flat % segs, x, dt, substeps, params, knots, coef, starts, lens, init,
            out_u, out_t,
        )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def simulate_segments_serial(  # type: ignore[no-untyped-def]
    x, dt, substeps, params, knots, coef, starts, lens, init, out_u, out_t
):
    """``simulate_segments_into`` on the calling thread, without the GIL (traces side by side)."""
    segs = starts.shape[0]
    for flat in range(params.shape[0] * segs):
        _segment_into(
            flat // segs, flat % segs, x, dt, substeps, params, knots, coef, starts, lens, init,
            out_u, out_t,
        )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _segment_into(b, s, x, dt, substeps, params, knots, coef, starts, lens, init, out_u, out_t):  # type: ignore[no-untyped-def]
    """Segment s of set b of ``simulate_segments_into``."""
    p = params[b]
    n = lens[s]
    xs = x[starts[s] : starts[s] + n]
    u0, v0 = init[b, s, 0], init[b, s, 1]
    scratch_v = np.empty(n)
    ou = out_u[b, s]
    ot = out_t[b, s]
    if starts[s] == 0:  # from static rest, exactly as an open-loop run
        simulate_into(xs, dt, substeps, p, knots, coef, ou, scratch_v, ot)
    else:
        ou[0] = u0
        scratch_v[0] = v0
        xd = (xs[1] - xs[0]) / dt if n > 1 else 0.0
        delta = p[P_PRELOAD] + xs[0] - p[P_PROJ] * u0
        t0 = p[P_STIFF] * delta + p[P_DAMP] * (xd - p[P_PROJ] * v0)
        ot[0] = t0 if delta > 0.0 and t0 > 0.0 else 0.0
        if n > 1:
            advance_into(xs, dt, substeps, p, knots, coef, u0, v0, True, ou, scratch_v, ot)
    for i in range(n, ou.shape[0]):
        ou[i] = ou[n - 1]
        ot[i] = ot[n - 1]
