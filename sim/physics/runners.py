"""The runners: from rest, a batch, segments from measured starts, chained, block by block.

A part of the compiled model's text, never run as itself (``kernel.py`` says how it is
composed). One set of runners for every set of terms: the baseline's are these with no
terms composed in.
"""

from __future__ import annotations

# <imports>
import numpy as np
from numba import njit, prange

from sim.physics.fibre import _sample_out, _set_taut, _zone, pack, rest_state
from sim.physics.integrator import _step, _substeps
from sim.physics.kernel import (
    NCARRY,
    _carry_out,
    _terms_given_at,
    _terms_given_end,
    _terms_given_start,
    _terms_start,
    _terms_start_state,
    _tuple_of,
    _with_carried,
)
from sim.physics.layout import *

# </imports>


@njit(cache=True, error_model="numpy")
def advance_into(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    """Integrate from the state (array of NY; discrete part in c) at x[0] over x[1:].

    Writes u, v and the drive- and weight-side tensions after each sample into
    out_*[i + 1] and the final state back into ``state`` and c, so a run can go on block
    by block. Returns the largest number of substeps one interval took.
    """
    return _advance(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2, np.empty(0))


@njit(cache=True, error_model="numpy")
def _advance(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2, inputs):  # type: ignore[no-untyped-def]
    """``advance_into``; with ``inputs`` (one per sample of x) a term's recorded input.

    A term may follow a recorded input instead of its own law (the pulley jump: the seat
    the *recorded* slack episodes put the fibre in, its ``measured_seats`` at every
    sample): over the interval after sample i the term is given inputs[i + 1], the
    recording up to sample i read (``_terms_given_*``). Without, the term follows the
    model (the seat the model's own slack gives).
    """
    y = _tuple_of(state)
    c[S_ZONE] = _zone(y[Y_V], c)
    given = _terms_given_start(c, inputs.shape[0] >= x.shape[0])
    most = 0
    for i in range(x.shape[0] - 1):
        xd = (x[i + 1] - x[i]) / dt
        if given:
            _terms_given_at(c, inputs[i + 1])
        nsub = _substeps(c, y, x[i], xd, dt, substeps)
        most = max(most, nsub)
        h = dt / nsub
        for j in range(nsub):
            y = _step(c, y, x[i] + xd * j * h, xd, h)
        _sample_out(c, y, x[i + 1], xd, i + 1, out_u, out_v, out_t1, out_t2)
    for k in range(NY):
        state[k] = y[k]
    _terms_given_end(c)
    return most


@njit(cache=True, error_model="numpy")
def simulate_into(x, dt, substeps, row, knots, coef, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    """Integrate one parameter row from static rest over the drive samples x (relative)."""
    return _from_rest(x, dt, substeps, row, knots, coef, out_u, out_v, out_t1, out_t2, np.empty(0))


@njit(cache=True, error_model="numpy")
def _from_rest(x, dt, substeps, row, knots, coef, out_u, out_v, out_t1, out_t2, inputs):  # type: ignore[no-untyped-def]
    """``simulate_into``, a term's input given as in ``_advance``."""
    c = pack(row, knots, coef)
    y = rest_state(c)
    out_u[0] = y[Y_U]
    out_v[0] = y[Y_V]
    out_t1[0] = c[D_K1] * (c[D_D10] + x[0])  # unclamped, no rate term (as always)
    out_t2[0] = out_t1[0] if c[D_NSEG] < 1.5 else c[D_K2] * c[D_D20]
    state = np.empty(NY)
    for k in range(NY):
        state[k] = y[k]
    return _advance(x, dt, substeps, c, state, out_u, out_v, out_t1, out_t2, inputs)


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_batch_into(x, dt, substeps, rows, knots, coef, out_u, out_v, out_t1, out_t2):  # type: ignore[no-untyped-def]
    """simulate_into for each row (and row of x, unless x has one row), in parallel."""
    for b in prange(rows.shape[0]):
        xb = x[b] if x.shape[0] > 1 else x[0]
        simulate_into(
            xb, dt, substeps, rows[b], knots, coef, out_u[b], out_v[b], out_t1[b], out_t2[b]
        )


@njit(cache=True, error_model="numpy")
def measured_state(c, x, xd, m):  # type: ignore[no-untyped-def]
    """A full state from a measured start m (columns I_*) at drive x (m), rate xd (m/s).

    Measured: weight u (m), v (m/s) and the drive-side force F (N). The effects' own
    states are not measured and take quasi-static values, each term's from its
    ``start_state`` hook (its continuous states, from the measured
    values and the columns the caller filled, e.g. I_HP) and its ``start`` hook (its
    discrete state in c); ``simulate_chained_into`` replaces the carried ones by the
    previous segment's. Sets the discrete state in c; returns the continuous state tuple.
    """
    u, v, force = m[I_U], m[I_V], m[I_F]
    taut = force > 0.25 * c[D_T0]
    y = _terms_start_state(c, x, xd, u, v, force, taut, m)  # the terms' own states
    _terms_start(c, y, x, xd, m)  # and their discrete states
    return y


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_chained_into(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
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
        _chain_into(
            b, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
        )


@njit(cache=True, nogil=True, error_model="numpy")
def simulate_chained_serial(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
):
    """``simulate_chained_into`` on the calling thread, without the GIL (traces side by side)."""
    for b in range(rows.shape[0]):
        _chain_into(
            b, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
        )


@njit(cache=True, error_model="numpy")
def _chain_into(  # type: ignore[no-untyped-def]
    b, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
):
    """Row b of ``simulate_chained_into``: its segments one after the other."""
    segs = starts.shape[0]
    carried = np.zeros(NCARRY)
    have = False
    for s in range(segs):
        n = lens[s]
        xs = x[starts[s] : starts[s] + n]
        ou, ot = out_u[b, s], out_t1[b, s]
        given = inputs[b, starts[s] : starts[s] + n]  # empty: the model's own law
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
                xs[:h1], dt, substeps, c, state, ou[:h1], sv[:h1], ot[:h1], st2[:h1], given[:h1]
            )
            _carry_out(state, carried)
            have = True
            tail = slice(hand, n)
            _advance(
                xs[tail], dt, substeps, c, state, ou[tail], sv[tail], ot[tail], st2[tail],
                given[tail],
            )  # fmt: skip
        elif n > 1:
            _advance(xs, dt, substeps, c, state, ou, sv, ot, st2, given)
        for i in range(n, ou.shape[0]):
            ou[i] = ou[n - 1]
            ot[i] = ot[n - 1]


@njit(cache=True, parallel=True, error_model="numpy")
def simulate_segments_into(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
):
    """Many short runs (segments) of many rows, in parallel over (set, segment).

    Segment s covers samples starts[s] … starts[s] + lens[s] − 1 of the relative drive
    x. A segment at sample 0 starts from static rest (as ``simulate_into``); any other
    from ``measured_state`` of init[b, s] (columns I_*). Writes u and the drive-side
    tension into out_*[b, s, :lens[s]], the last value held to the end of the row.
    inputs[b] (one per sample of x, or none): a term's recorded input the runs follow
    (``_advance``: the pulley seat).
    """
    segs = starts.shape[0]
    for flat in prange(rows.shape[0] * segs):
        _segment_into(
            flat // segs, flat % segs, x, dt, substeps, rows, knots, coef, starts, lens, init,
            out_u, out_t1, inputs,
        )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def simulate_segments_serial(  # type: ignore[no-untyped-def]
    x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
):
    """``simulate_segments_into`` on the calling thread, without the GIL (traces side by side)."""
    segs = starts.shape[0]
    for flat in range(rows.shape[0] * segs):
        _segment_into(
            flat // segs, flat % segs, x, dt, substeps, rows, knots, coef, starts, lens, init,
            out_u, out_t1, inputs,
        )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _segment_into(  # type: ignore[no-untyped-def]
    b, s, x, dt, substeps, rows, knots, coef, starts, lens, init, out_u, out_t1, inputs
):
    """Segment s of row b of ``simulate_segments_into``."""
    n = lens[s]
    xs = x[starts[s] : starts[s] + n]
    ou = out_u[b, s]
    ot = out_t1[b, s]
    given = inputs[b, starts[s] : starts[s] + n]  # empty: the model's own law
    sv, st2 = np.empty(n), np.empty(n)
    if starts[s] == 0:
        _from_rest(xs, dt, substeps, rows[b], knots, coef, ou, sv, ot, st2, given)
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
            _advance(xs, dt, substeps, c, state, ou, sv, ot, st2, given)
    for i in range(n, ou.shape[0]):
        ou[i] = ou[n - 1]
        ot[i] = ot[n - 1]
