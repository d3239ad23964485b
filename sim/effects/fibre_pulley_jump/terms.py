"""The pulley jump's terms: the seat's offset in the fibre and its law after slack episodes.

A part of the compiled model's text, never run as itself: ``sim.physics.compose`` appends
it to a model composed with this term and calls its hooks (``pj_<hook>``, signatures in
``sim.physics.kernel_source.HOOKS``) from the integrator and the runners. Its discrete
state lives in c: ``S_LOFF`` the seat's offset (the weight-side segment's extra length),
``S_LBASE`` the seat before the episode, ``S_DEPTH`` the episode's deepest slack,
``S_SLACKT`` its length so far, ``S_RECSEAT`` 1.0 while a run follows the recorded seat.
Its imports are for reading and linting only.
"""

from __future__ import annotations

# <imports>
import math

import numpy as np
from numba import njit

from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def pj_extension(c, y, ext1, rate1, ext2, rate2):  # type: ignore[no-untyped-def]
    """The weight-side segment is longer by the seat's offset."""
    if c[R_PJ_ON] > 0.0:
        ext2 += c[S_LOFF]
    return ext1, rate1, ext2, rate2


@njit(cache=True, error_model="numpy")
def pj_after_part(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """The seat after an integrated part (h seconds) of a step: the model's own slack."""
    if c[R_PJ_ON] > 0.0 and c[S_RECSEAT] == 0.0:
        # The weight-side segment carries the seat (one segment: S_TAUT2 is only
        # refreshed at a step's start; S_TAUT1 follows every located switch).
        taut = c[S_TAUT2] if c[D_NSEG] > 1.5 else c[S_TAUT1]
        _reseat(c, taut <= 0.0, c[P_PRELOAD] + x - c[P_PROJ] * y[Y_U], h)


@njit(cache=True, error_model="numpy")
def pj_given_start(c, given):  # type: ignore[no-untyped-def]
    """Whether a run follows the recorded seat (``given``: one per sample of its drive)."""
    follows = given and c[R_PJ_ON] > 0.0
    c[S_RECSEAT] = 1.0 if follows else 0.0
    return follows


@njit(cache=True, error_model="numpy")
def pj_given_at(c, value):  # type: ignore[no-untyped-def]
    """The recorded seat over the next interval."""
    c[S_LOFF] = value


@njit(cache=True, error_model="numpy")
def pj_given_end(c):  # type: ignore[no-untyped-def]
    """The run is over: a later block follows the model's own slack again."""
    c[S_RECSEAT] = 0.0


@njit(cache=True, error_model="numpy")
def pj_start(c, y, x, xd, m):  # type: ignore[no-untyped-def]
    """The seat at a segment's measured start (``measured_seats``, in m's I_LOFF … I_SLACKT).

    From the recorded slack episodes: a seat estimated from the measured elongation at
    the start, rounded to one of the two grooves, picked the wrong groove often enough to
    cost 340× the open-loop error on a clean recording.
    """
    c[S_LOFF], c[S_LBASE], c[S_DEPTH], c[S_SLACKT] = m[I_LOFF], m[I_LBASE], m[I_DEPTH], m[I_SLACKT]


@njit(cache=True, error_model="numpy")
def _reseat(c, slack, elongation, h):  # type: ignore[no-untyped-def]
    """The pulley seat after h seconds more of a slack (or taut) fibre.

    The fibre leaves its groove once its loop is ``onset`` deep and has lain slack for
    ``dwell`` (held by groove friction, it needs time to slide out), and has moved over to
    the next seat within a few depth scales more: with ``seats`` = 0 the other of two
    grooves (it toggles), else one more step up the groove's flank, up to ``seats`` steps
    (the flange), where it stays. The seat follows the episode's deepest geometric slack,
    so it never moves back within one episode; when the fibre is taut again it stays where
    it is. The same law runs on the model's slack (``pj_after_part``) and on the recorded
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
