"""The baseline model's compiled integrator (STAND.md §2).

State (u, v): weight displacement up the incline and its velocity. The drive position x
is given at the sample times and is linear inside each sample interval, so every RK4
step sees a smooth right-hand side. The fibre is either *taut* (T = k·δ + c·δ̇) or
*slack* (T = 0); the switch is an event located inside the step:

* taut → slack when k·δ + c·δ̇ falls through 0 (T is continuous there);
* slack → taut when δ rises through 0 (T jumps by c·δ̇), or when δ > 0 and k·δ + c·δ̇
  rises through 0.

The step is split at the located crossing and each part is integrated with its own
right-hand side, so the jump costs the method no order. Crossings are found on the
cubic Hermite interpolant of the step (fourth-order accurate, like the step itself).

Parameter vector layout (one row per parameter set) is given by the P_* indices.
"""

from __future__ import annotations

from numba import njit, prange

P_MASS, P_PROJ, P_STIFF, P_DAMP, P_FRICTION_N, P_GRAVITY_N, P_PRELOAD, P_VREG = range(8)
N_PARAMS = 8


@njit(cache=True, error_model="numpy")
def _mu(speed, knots, coef):  # type: ignore[no-untyped-def]
    n = knots.shape[0]
    if speed <= knots[0]:
        return coef[3, 0]
    if speed >= knots[n - 1]:
        s = knots[n - 1] - knots[n - 2]
        i = n - 2
        return ((coef[0, i] * s + coef[1, i]) * s + coef[2, i]) * s + coef[3, i]
    i = 0
    while speed > knots[i + 1]:
        i += 1
    s = speed - knots[i]
    return ((coef[0, i] * s + coef[1, i]) * s + coef[2, i]) * s + coef[3, i]


@njit(cache=True, error_model="numpy")
def _friction(v, p, knots, coef):  # type: ignore[no-untyped-def]
    fn = p[P_FRICTION_N]
    if fn == 0.0:
        return 0.0
    vreg = p[P_VREG]
    if v >= vreg:
        return fn * _mu(v, knots, coef)
    if v <= -vreg:
        return -fn * _mu(-v, knots, coef)
    return fn * _mu(vreg, knots, coef) * v / vreg


@njit(cache=True, error_model="numpy")
def _accel(u, v, x, xd, taut, p, knots, coef):  # type: ignore[no-untyped-def]
    tension = 0.0
    if taut:
        n = p[P_PROJ]
        tension = p[P_STIFF] * (p[P_PRELOAD] + x - n * u) + p[P_DAMP] * (xd - n * v)
        return (n * tension - p[P_GRAVITY_N] - _friction(v, p, knots, coef)) / p[P_MASS]
    return (-p[P_GRAVITY_N] - _friction(v, p, knots, coef)) / p[P_MASS]


@njit(cache=True, error_model="numpy")
def _rk4(u, v, x0, xd, h, taut, p, knots, coef):  # type: ignore[no-untyped-def]
    a1 = _accel(u, v, x0, xd, taut, p, knots, coef)
    u2 = u + 0.5 * h * v
    v2 = v + 0.5 * h * a1
    xm = x0 + 0.5 * h * xd
    a2 = _accel(u2, v2, xm, xd, taut, p, knots, coef)
    u3 = u + 0.5 * h * v2
    v3 = v + 0.5 * h * a2
    a3 = _accel(u3, v3, xm, xd, taut, p, knots, coef)
    u4 = u + h * v3
    v4 = v + h * a3
    a4 = _accel(u4, v4, x0 + h * xd, xd, taut, p, knots, coef)
    un = u + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
    vn = v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return un, vn, a1


@njit(cache=True, error_model="numpy")
def _switch_fn(theta, u0, v0, a0, u1, v1, a1, x0, xd, h, which, p):  # type: ignore[no-untyped-def]
    # Cubic Hermite interpolants of u and v over the step, θ ∈ [0, 1].
    t2 = theta * theta
    t3 = t2 * theta
    h00 = 2 * t3 - 3 * t2 + 1
    h10 = t3 - 2 * t2 + theta
    h01 = -2 * t3 + 3 * t2
    h11 = t3 - t2
    u = h00 * u0 + h10 * h * v0 + h01 * u1 + h11 * h * v1
    v = h00 * v0 + h10 * h * a0 + h01 * v1 + h11 * h * a1
    n = p[P_PROJ]
    delta = p[P_PRELOAD] + x0 + xd * theta * h - n * u
    if which == 0:
        return delta
    return p[P_STIFF] * delta + p[P_DAMP] * (xd - n * v)


@njit(cache=True, error_model="numpy")
def _locate(u0, v0, a0, u1, v1, a1, x0, xd, h, which, p):  # type: ignore[no-untyped-def]
    lo = 0.0
    hi = 1.0
    g_lo = _switch_fn(lo, u0, v0, a0, u1, v1, a1, x0, xd, h, which, p)
    for _ in range(48):
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
def _step(u, v, taut, x0, xd, h, p, knots, coef):  # type: ignore[no-untyped-def]
    """Advance one step of length h, splitting it at regime switches."""
    remaining = h
    xs = x0
    for _ in range(4):  # more than 4 switches inside one sub-millisecond step is not physical
        un, vn, a0 = _rk4(u, v, xs, xd, remaining, taut, p, knots, coef)
        x_end = xs + xd * remaining
        n = p[P_PROJ]
        delta_end = p[P_PRELOAD] + x_end - n * un
        force_end = p[P_STIFF] * delta_end + p[P_DAMP] * (xd - n * vn)
        if taut:
            switch = force_end < 0.0
            which = 1
        else:
            switch = delta_end > 0.0 and force_end > 0.0
            delta_start = p[P_PRELOAD] + xs - n * u
            which = 0 if delta_start <= 0.0 else 1
        if not switch:
            return un, vn, taut
        a1 = _accel(un, vn, x_end, xd, taut, p, knots, coef)
        theta = _locate(u, v, a0, un, vn, a1, xs, xd, remaining, which, p)
        part = theta * remaining
        u, v, _ = _rk4(u, v, xs, xd, part, taut, p, knots, coef)
        xs = xs + xd * part
        remaining = remaining - part
        taut = not taut
        if remaining <= 1e-15:
            return u, v, taut
    un, vn, _ = _rk4(u, v, xs, xd, remaining, taut, p, knots, coef)
    return un, vn, _taut_now(un, vn, xs + xd * remaining, xd, p)


@njit(cache=True, error_model="numpy")
def advance_into(x, dt, substeps, p, knots, coef, u, v, taut, out_u, out_v, out_t):  # type: ignore[no-untyped-def]
    """Integrate from state (u, v, taut) at x[0] over the samples x[1:], in place.

    Writes the state after each sample into out_*[i + 1] and returns the final state, so
    a long run can be advanced block by block (the simulated stand does). Time is i·dt,
    never summed.
    """
    n = p[P_PROJ]
    h = dt / substeps
    for i in range(x.shape[0] - 1):
        xd = (x[i + 1] - x[i]) / dt
        for j in range(substeps):
            u, v, taut = _step(u, v, taut, x[i] + xd * j * h, xd, h, p, knots, coef)
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
