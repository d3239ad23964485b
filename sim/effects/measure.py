"""Measurement-side effects: what the gauges do to the true u and F (STAND.md §5).

* ``dial_gauge_calibration``: u_rec = (1 + gain_error)·u + offset.
* ``force_gauge_dynamics``: F_rec is F through a second-order low-pass
  ω²/(s² + 2ζωs + ω²), discretised exactly for an input linear between samples
  (first-order hold), starting settled at the first sample.
* ``channel_time_skew``: a channel is sampled Δt late (Δt < 0: early): its value at
  t_i − Δt, interpolated linearly between samples and held beyond the run's ends.

The order is the physical one: the gauge filters, then the recorder samples (skew).
Each function works on a whole run or block by block with carried state, with identical
arithmetic either way (``sim.physics.runs.Stream`` relies on that).
The numba code here is self-contained (see ``sim/physics/kernel.py`` on numba's cache);
the row's columns are read in plain Python (``measurement_rows``), never in it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from sim.physics.layout import (
    R_CS_DISP,
    R_CS_FORCE,
    R_CS_ON,
    R_DG_GAIN,
    R_DG_OFFSET,
    R_DG_ON,
    R_FG_FC,
    R_FG_ON,
    R_FG_ZETA,
)

FloatArray = NDArray[np.float64]

#: Columns of a measurement row (see ``measurement_rows``).
(M_DG_ON, M_GAIN, M_OFFSET, M_FG_ON, M_FC, M_ZETA, M_CS_ON, M_SKEW_F, M_SKEW_U) = range(9)
N_MROW = 9


def measurement_rows(rows: FloatArray) -> FloatArray:
    """The measurement columns of kernel parameter rows (sets, N_ROW) → (sets, N_MROW)."""
    cols = [R_DG_ON, R_DG_GAIN, R_DG_OFFSET, R_FG_ON, R_FG_FC, R_FG_ZETA]
    cols += [R_CS_ON, R_CS_FORCE, R_CS_DISP]
    return np.ascontiguousarray(np.atleast_2d(rows)[:, cols], dtype=np.float64)


@njit(cache=True, error_model="numpy")
def _matmul4(a, b, out):  # type: ignore[no-untyped-def]
    for i in range(4):
        for j in range(4):
            acc = 0.0
            for k in range(4):
                acc += a[i, k] * b[k, j]
            out[i, j] = acc


@njit(cache=True, error_model="numpy")
def _expm4(a):  # type: ignore[no-untyped-def]
    """exp(a) of a 4×4 matrix: scaling and squaring with an 18-term Taylor series.

    Written with scalar loops: numpy matrix products here cost seconds of compile time.
    """
    norm = 0.0
    for i in range(4):
        row = 0.0
        for j in range(4):
            row += abs(a[i, j])
        norm = max(norm, row)
    squarings = math.ceil(math.log2(norm / 0.25)) if norm > 0.25 else 0
    scale = 0.5**squarings
    result = np.zeros((4, 4))
    term = np.zeros((4, 4))
    tmp = np.zeros((4, 4))
    b = np.zeros((4, 4))
    for i in range(4):
        result[i, i] = 1.0
        term[i, i] = 1.0
        for j in range(4):
            b[i, j] = a[i, j] * scale
    for k in range(1, 18):
        _matmul4(term, b, tmp)
        for i in range(4):
            for j in range(4):
                term[i, j] = tmp[i, j] / k
                result[i, j] += term[i, j]
    for _ in range(squarings):
        _matmul4(result, result, tmp)
        for i in range(4):
            for j in range(4):
                result[i, j] = tmp[i, j]
    return result


@njit(cache=True, error_model="numpy")
def gauge_coefficients(cutoff_hz, zeta, dt):  # type: ignore[no-untyped-def]
    """(Φ, Γ₀, Γ₁) of x_{k+1} = Φx_k + Γ₀F_k + Γ₁(F_{k+1} − F_k)/dt, state x = (y, ẏ)."""
    w = 2.0 * math.pi * cutoff_hz
    m = np.zeros((4, 4))
    m[0, 1] = dt
    m[1, 0] = -w * w * dt
    m[1, 1] = -2.0 * zeta * w * dt
    m[1, 2] = w * w * dt
    m[2, 3] = dt
    return _expm4(m)


@njit(cache=True, error_model="numpy")
def gauge_filter_into(force, dt, cutoff_hz, zeta, state, out):  # type: ignore[no-untyped-def]
    """Low-pass ``force`` into ``out``; state = (y, ẏ, previous input), updated in place."""
    e = gauge_coefficients(cutoff_hz, zeta, dt)  # Φ = e[:2, :2], Γ₀ = e[:2, 2], Γ₁ = e[:2, 3]
    y, yd, prev = state[0], state[1], state[2]
    for k in range(force.shape[0]):
        slope = (force[k] - prev) / dt
        y, yd = (
            e[0, 0] * y + e[0, 1] * yd + e[0, 2] * prev + e[0, 3] * slope,
            e[1, 0] * y + e[1, 1] * yd + e[1, 2] * prev + e[1, 3] * slope,
        )
        prev = force[k]
        out[k] = y
    state[0], state[1], state[2] = y, yd, prev


@njit(cache=True, error_model="numpy")
def skew_into(series, start, delay_samples, out):  # type: ignore[no-untyped-def]
    """out[k] ← series at index start + k − delay (linear; held beyond the series' ends)."""
    whole = math.floor(delay_samples)
    frac = delay_samples - whole  # in [0, 1): weight of the earlier neighbour
    last = series.shape[0] - 1
    for k in range(out.shape[0]):
        j = start + k - int(whole)  # the later neighbour
        if j <= 0:
            out[k] = series[0]
        elif j > last:
            out[k] = series[last]
        else:
            out[k] = (1.0 - frac) * series[j] + frac * series[j - 1]


@njit(cache=True, error_model="numpy")
def measure_into(u, force, dt, m, gauge0, out_u, out_f):  # type: ignore[no-untyped-def]
    """Apply one measurement row to a run.

    ``gauge0``: the force gauge's output and its rate at the first sample (N, N/s), as
    recorded; NaN: settled on the run's first force (a run from rest).
    """
    n = u.shape[0]
    gu = np.empty(n)
    gf = np.empty(n)
    for k in range(n):
        gu[k] = (1.0 + m[M_GAIN]) * u[k] + m[M_OFFSET] if m[M_DG_ON] > 0.0 else u[k]
        gf[k] = force[k]
    if m[M_FG_ON] > 0.0:
        state = np.empty(3)
        if math.isnan(gauge0[0]):
            state[0], state[1], state[2] = force[0], 0.0, force[0]
        else:  # the state one sample before, so that the first output is gauge0[0]
            state[0], state[1], state[2] = gauge0[0] - gauge0[1] * dt, gauge0[1], force[0]
        gauge_filter_into(force, dt, m[M_FC], m[M_ZETA], state, gf)
    if m[M_CS_ON] > 0.0:
        skew_into(gu, 0, m[M_SKEW_U] / dt, out_u)
        skew_into(gf, 0, m[M_SKEW_F] / dt, out_f)
    else:
        for k in range(n):
            out_u[k] = gu[k]
            out_f[k] = gf[k]


@njit(cache=True, error_model="numpy")
def measure_batch_into(u, force, dt, mrows, gauge0, out_u, out_f):  # type: ignore[no-untyped-def]
    """measure_into for each row (sequential: ≈ 50 µs a row, not worth threads)."""
    for b in range(mrows.shape[0]):
        measure_into(u[b], force[b], dt, mrows[b], gauge0[b], out_u[b], out_f[b])
