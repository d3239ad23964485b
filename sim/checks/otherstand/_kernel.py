"""The other stand's compiled dynamics: STAND.md §2 plus the physical second formulations.

Fixed-step classical RK4 at a fine internal step (25 µs at 2 kHz with the default
oversampling), the drive linear between samples. The tension-only law switches when a
fibre segment goes slack or taut; the segment's mode is frozen within a step and a step
that crosses the switch is cut at the (secant-located) crossing, so the jump of the
damping term c·δ̇ at re-tensioning costs no order of accuracy. Stick/slip switches of the
Karnopp friction laws are left to the fine step (their band keeps them continuous enough).

State vector (``N_STATE``): u, v (weight), s, w (pulley rim), q (Maxwell branches, two per
fibre segment), p (seat length change), a and ȧ (three string modes of each free span),
z and ż (the drive anchor, for the out-of-catalogue terms).
Parameter row: the ``P_*`` indices below, filled by ``sim.checks.otherstand.stand``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Parameter row indices.
(P_M, P_K, P_C, P_N, P_MGS, P_T0, P_NORMAL, P_VREG, P_G, P_L1, P_L2, P_SEG1, P_SEG2, P_LTOT,
 P_MU, P_VE_ON, P_KA, P_TAUA, P_KB, P_TAUB, P_TV_ON, P_ETA, P_DRAG, P_GP1, P_GP2, P_EXC,
 P_PJ_ON, P_STEP, P_THR, P_TAUS, P_SEATS, P_SHARE, P_PI_ON, P_MP, P_FK, P_FS, P_CV,
 P_SS_ON, P_RATIO, P_VS, P_EXP, P_SL_ON, P_MUW, P_SINB, P_PEXP, P_TSTICK, P_VBAND,
 P_HARD, P_WAVE_A, P_WAVE_K, P_WAVE_PH, P_VISC, P_QDRAG, P_FR_ON, P_FR_W, P_FR_Z, P_FR_M,
 N_PARAM) = range(58)  # fmt: skip
# P_HARD … P_FR_M: the out-of-catalogue terms (``sim.checks.otherstand.outside``): the fibre's
# strain stiffening, a force along a wavy guide, viscous and quadratic drag on the
# weight, and a compliant drive anchor (a mode of its own, frequency, damping, mass).

# State indices.
S_U, S_V, S_S, S_W, S_Q, S_P, S_A = 0, 1, 2, 3, 4, 8, 9
N_MODES = 3
#: Reference tension of the side load's nonlinearity, N (see the effect's docstring).
SIDE_REF_N = 50.0
S_AD = S_A + 2 * N_MODES
#: The drive anchor's displacement towards the pulley and its rate (``P_FR_ON``).
S_Z = S_AD + 2 * N_MODES
N_STATE = S_Z + 2


@njit(cache=True)
def _mu(speed, tab_x, tab_c):  # type: ignore[no-untyped-def]
    """The friction table's μ at a speed (PCHIP pieces, constant beyond the ends)."""
    last = tab_x.shape[0] - 1
    if speed <= tab_x[0]:
        s = tab_x[0]
    elif speed >= tab_x[last]:
        s = tab_x[last]
    else:
        s = speed
    j = 0
    while j < last - 1 and s > tab_x[j + 1]:
        j += 1
    h = s - tab_x[j]
    return ((tab_c[0, j] * h + tab_c[1, j]) * h + tab_c[2, j]) * h + tab_c[3, j]


@njit(cache=True)
def _stretch(y, p, arest, span):  # type: ignore[no-untyped-def]
    """Path length the span's modes add (from rest) and its rate."""
    ell = p[P_L1] if span == 0 else p[P_L2]
    s = 0.0
    sd = 0.0
    for m in range(N_MODES):
        kk = (m + 1) * math.pi
        a = y[S_A + span * N_MODES + m]
        ad = y[S_AD + span * N_MODES + m]
        ar = arest[span * N_MODES + m]
        s += kk * kk * (a * a - ar * ar) / (4.0 * ell)
        sd += kk * kk * a * ad / (2.0 * ell)
    return s, sd


@njit(cache=True)
def elongations(y, x, xd, p, arest, target, out):  # type: ignore[no-untyped-def]
    """Elongation and its rate of each fibre segment → out[0:2], out[2:4]; count of segs."""
    n = p[P_N]
    pdot = (target - y[S_P]) / p[P_TAUS] if p[P_PJ_ON] > 0 else 0.0
    s0, sd0 = (0.0, 0.0)
    s1, sd1 = (0.0, 0.0)
    if p[P_TV_ON] > 0:
        s0, sd0 = _stretch(y, p, arest, 0)
        s1, sd1 = _stretch(y, p, arest, 1)
    # A compliant anchor takes its displacement off the drive's end of the fibre.
    x = x - y[S_Z]
    xd = xd - y[S_Z + 1]
    if p[P_PI_ON] > 0:
        k1 = p[P_K] * p[P_LTOT] / p[P_SEG1]
        k2 = p[P_K] * p[P_LTOT] / p[P_SEG2]
        share = p[P_SHARE]
        out[0] = p[P_T0] / k1 + x - y[S_S] + share * y[S_P] + s0
        out[2] = xd - y[S_W] + share * pdot + sd0
        out[1] = p[P_T0] / k2 + y[S_S] - n * y[S_U] + (1.0 - share) * y[S_P] + s1
        out[3] = y[S_W] - n * y[S_V] + (1.0 - share) * pdot + sd1
        return 2
    out[0] = p[P_T0] / p[P_K] + x - n * y[S_U] + y[S_P] + s0 + s1
    out[2] = xd - n * y[S_V] + pdot + sd0 + sd1
    return 1


@njit(cache=True)
def _karnopp(v, applied, static, mass, p):  # type: ignore[no-untyped-def]
    """Acceleration inside the stick band: held (decaying) while the friction can hold."""
    if abs(applied) <= static:
        return -v / p[P_TSTICK]
    return (applied - math.copysign(static, applied)) / mass


@njit(cache=True)
def rhs(y, x, xd, p, tab_x, tab_c, arest, taut, target, dy, tens):  # type: ignore[no-untyped-def]
    """dy = f(y) with segment modes ``taut`` frozen; tens = (drive-side, weight-side) T."""
    el = np.empty(4)
    nseg = elongations(y, x, xd, p, arest, target, el)
    for i in range(4):
        dy[i] = 0.0
    dy[S_P] = (target - y[S_P]) / p[P_TAUS] if p[P_PJ_ON] > 0 else 0.0
    for seg in range(nseg):
        scale = p[P_LTOT] / (p[P_SEG1] if seg == 0 else p[P_SEG2]) if nseg == 2 else 1.0
        d = el[seg]
        dd = el[2 + seg]
        t = 0.0
        qa = S_Q + 2 * seg
        if taut[seg]:
            elastic = p[P_K] * d * (1.0 + p[P_HARD] * p[P_K] * d / SIDE_REF_N)
            t = scale * (elastic + p[P_C] * dd) + y[qa] + y[qa + 1]
            t = max(t, 0.0)
        if p[P_VE_ON] > 0:
            rate = dd if taut[seg] else 0.0
            dy[qa] = scale * p[P_KA] * rate - y[qa] / p[P_TAUA]
            dy[qa + 1] = scale * p[P_KB] * rate - y[qa + 1] / p[P_TAUB]
        else:
            dy[qa] = 0.0
            dy[qa + 1] = 0.0
        tens[seg] = t
    if nseg == 1:
        tens[1] = tens[0]
        dy[S_Q + 2] = 0.0
        dy[S_Q + 3] = 0.0
    tw = tens[1]
    # The weight.
    v = y[S_V]
    m = p[P_M]
    applied = p[P_N] * tw - p[P_MGS]
    side = 0.0
    if p[P_SL_ON] > 0 and tw > 0:
        side = p[P_MUW] * p[P_SINB] * tw * (tw / SIDE_REF_N) ** (p[P_PEXP] - 1.0)
    speed = abs(v)
    if p[P_SS_ON] > 0:
        f0 = p[P_NORMAL] * _mu(0.0, tab_x, tab_c)
        if speed < p[P_VBAND]:
            acc = _karnopp(v, applied, (1.0 + p[P_RATIO]) * f0 + side, m, p)
        else:
            hump = p[P_RATIO] * f0 * math.exp(-((speed / p[P_VS]) ** p[P_EXP]))
            fr = p[P_NORMAL] * _mu(speed, tab_x, tab_c) + hump + side
            acc = (applied - math.copysign(fr, v)) / m
    else:
        vreg = p[P_VREG]
        if speed >= vreg:
            fr = math.copysign(p[P_NORMAL] * _mu(speed, tab_x, tab_c) + side, v)
        else:
            fr = (p[P_NORMAL] * _mu(vreg, tab_x, tab_c) + side) * v / vreg
        acc = (applied - fr) / m
    if p[P_WAVE_A] != 0.0:
        acc += p[P_WAVE_A] * math.sin(p[P_WAVE_K] * y[S_U] + p[P_WAVE_PH]) / m
    acc -= (p[P_VISC] * v + p[P_QDRAG] * v * abs(v)) / m
    dy[S_U] = v
    dy[S_V] = acc
    # The drive anchor: pulled towards the pulley by the tension beyond the preload.
    if p[P_FR_ON] > 0:
        w = p[P_FR_W]
        z = y[S_Z]
        zd = y[S_Z + 1]
        dy[S_Z] = zd
        dy[S_Z + 1] = (tens[0] - p[P_T0]) / p[P_FR_M] - w * w * z - 2.0 * p[P_FR_Z] * w * zd
    else:
        dy[S_Z] = 0.0
        dy[S_Z + 1] = 0.0
    # The pulley (rim coordinates).
    if p[P_PI_ON] > 0:
        w = y[S_W]
        net = tens[0] - tens[1]
        if abs(w) < p[P_VBAND]:
            dy[S_W] = _karnopp(w, net, p[P_FS], p[P_MP], p)
        else:
            dy[S_W] = (net - math.copysign(p[P_FK], w) - p[P_CV] * w) / p[P_MP]
        dy[S_S] = w
    # String modes: span 0 (drive side, tension tens[0]), span 1 (weight side, tens[1]).
    for span in range(2):
        ell = p[P_L1] if span == 0 else p[P_L2]
        tension = tens[span]
        gp = p[P_GP1] if span == 0 else p[P_GP2]
        end_acc = p[P_EXC] * acc if span == 1 else 0.0
        for mm in range(N_MODES):
            ia = S_A + span * N_MODES + mm
            iad = S_AD + span * N_MODES + mm
            if p[P_TV_ON] <= 0:
                dy[ia] = 0.0
                dy[iad] = 0.0
                continue
            order = mm + 1
            kk = order * math.pi / ell
            omega = kk * math.sqrt(tension / p[P_MU])
            load = 4.0 * gp / (order * math.pi) if order % 2 == 1 else 0.0
            sign = 1.0 if order % 2 == 1 else -1.0
            load -= 2.0 * sign * end_acc / (order * math.pi)
            a = y[ia]
            ad = y[iad]
            dy[ia] = ad
            dy[iad] = load - omega * omega * a - p[P_ETA] * omega * ad - p[P_DRAG] * ad * abs(ad)


@njit(cache=True)
def _rk4(y, x0, xd, h, p, tab_x, tab_c, arest, taut, target, out):  # type: ignore[no-untyped-def]
    n = y.shape[0]
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    tmp = np.empty(n)
    tens = np.empty(2)
    rhs(y, x0, xd, p, tab_x, tab_c, arest, taut, target, k1, tens)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    rhs(tmp, x0 + 0.5 * h * xd, xd, p, tab_x, tab_c, arest, taut, target, k2, tens)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    rhs(tmp, x0 + 0.5 * h * xd, xd, p, tab_x, tab_c, arest, taut, target, k3, tens)
    for i in range(n):
        tmp[i] = y[i] + h * k3[i]
    rhs(tmp, x0 + h * xd, xd, p, tab_x, tab_c, arest, taut, target, k4, tens)
    for i in range(n):
        out[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True)
def simulate_kernel(x, rate, over, sub, p, tab_x, tab_c, arest):  # type: ignore[no-untyped-def]
    """Run from static rest; outputs at rate·over: u, v, drive-side T, weight-side T, seat p.

    x: drive positions at ``rate`` (relative to the rest position).
    """
    n = x.shape[0]
    nout = (n - 1) * over + 1
    res = np.zeros((5, nout))
    y = np.zeros(N_STATE)
    for i in range(2 * N_MODES):
        y[S_A + i] = arest[i]
    ynew = np.empty(N_STATE)
    el = np.empty(4)
    el2 = np.empty(4)
    taut = np.ones(2, dtype=np.bool_)
    dy = np.empty(N_STATE)
    tens = np.empty(2)
    target = 0.0
    seat = 0.0
    armed = True
    res[2, 0] = p[P_T0]
    res[3, 0] = p[P_T0]
    h_out = 1.0 / (rate * over)
    h_sub = h_out / sub
    for i in range(n - 1):
        xd = (x[i + 1] - x[i]) * rate
        for j in range(over):
            for k in range(sub):
                tau_end = (j * sub + k + 1) * h_sub  # time within the sample interval
                tau = (j * sub + k) * h_sub
                while tau < tau_end - 1e-15:
                    hh = tau_end - tau
                    xs = x[i] + xd * tau
                    nseg = elongations(y, xs, xd, p, arest, target, el)
                    for s in range(nseg):
                        taut[s] = el[s] > 0.0
                    _rk4(y, xs, xd, hh, p, tab_x, tab_c, arest, taut, target, ynew)
                    elongations(ynew, xs + xd * hh, xd, p, arest, target, el2)
                    theta = 1.0
                    for s in range(nseg):
                        if (el[s] > 0.0) != (el2[s] > 0.0):
                            theta = min(theta, el[s] / (el[s] - el2[s]))
                    if theta < 1.0 and theta * hh > 1e-9:
                        hh = theta * hh
                        _rk4(y, xs, xd, hh, p, tab_x, tab_c, arest, taut, target, ynew)
                    for q in range(N_STATE):
                        y[q] = ynew[q]
                    tau += hh
                    # The seat ratchet: one seat per slack episode deeper than the threshold.
                    if p[P_PJ_ON] > 0:
                        nseg = elongations(y, x[i] + xd * tau, xd, p, arest, target, el)
                        depth = -el[0] if nseg == 1 else max(-el[0], -el[1])
                        if armed and depth > p[P_THR] and seat < p[P_SEATS] - 1.0:
                            seat += 1.0
                            target = seat * p[P_STEP]
                            armed = False
                        if depth < 0.0:
                            armed = True
            o = i * over + j + 1
            xs = x[i] + xd * (j + 1) * h_out
            nseg = elongations(y, xs, xd, p, arest, target, el)
            for s in range(nseg):
                taut[s] = el[s] > 0.0
            rhs(y, xs, xd, p, tab_x, tab_c, arest, taut, target, dy, tens)
            res[0, o] = y[S_U]
            res[1, o] = y[S_V]
            res[2, o] = tens[0]
            res[3, o] = tens[1]
            res[4, o] = y[S_P]
    return res
