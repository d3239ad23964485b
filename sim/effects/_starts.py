"""Segment start states from measurements, per kernel row (private: ``sim.model`` uses it).

A segment of a multiple-shooting run restarts from the state the gauges measured. What
the dial gauge reads is scaled by its gain G against the drive encoder, which the
recording itself shows (``Restarts.dial_slope``): every row restarts from u_rec/G, so a
gain error never becomes a wrong elongation (a wrong force) — it stays in the u channel,
where a candidate's dial gauge model maps the true u to the reading. A displacement
channel recorded Δt late shows the true u of Δt earlier, so the true u now is
u_rec(t + Δt) ≈ u_rec + Δt·v. The Maxwell branch's
state is its response to the measured elongation history; the pulley seat follows the
recorded slack episodes (``kernel.measured_seats``). The other effects' states are set
inside the kernel (``kernel.measured_state``) or carried between segments.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.signal import lfilter

from sim.effects import kernel as ek

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = ["start_states"]


def start_states(
    rows: FloatArray,
    x_rel_m: FloatArray,
    rate_hz: float,
    starts: IntArray,
    u_m: FloatArray,
    v_m_s: FloatArray,
    force_n: FloatArray,
    dial_slope: float = float("nan"),
) -> FloatArray:
    """Measured start states (sets, segments, ek.N_INIT) for augmented kernel rows.

    ``u_m``, ``v_m_s``, ``force_n``: the recorded channels (smoothed) at every sample;
    ``dial_slope``: du_rec/dx at constant force (NaN: take the gauge's scale as 1).
    """
    rows2 = np.atleast_2d(rows)
    init = np.zeros((rows2.shape[0], starts.size, ek.N_INIT))
    for b, row in enumerate(rows2):
        u, v = _true_u(row, u_m, v_m_s, dial_slope)
        init[b, :, ek.I_U] = u[starts]
        init[b, :, ek.I_V] = v[starts]
        init[b, :, ek.I_F] = force_n[starts]
        if row[ek.R_VE_ON] > 0:
            init[b, :, ek.I_HP] = _branch_elongation(row, x_rel_m, rate_hz, u_m)[starts]
        if row[ek.R_PJ_ON] > 0:
            # Slack: the force below 5 % of the rest tension, well above the gauge's noise
            # and hum (tenths of a newton) and far below a taut fibre's force.
            slack_n = 0.05 * row[ek.P_GRAVITY_N] / row[ek.P_PROJ]
            init[b, :, ek.I_LOFF : ek.I_SLACKT + 1] = ek.measured_seats(
                row, x_rel_m, u, force_n, 1.0 / rate_hz, slack_n, starts
            )
    return init


def _true_u(
    row: FloatArray, u_m: FloatArray, v_m_s: FloatArray, dial_slope: float
) -> tuple[FloatArray, FloatArray]:
    """The weight's u and v on the model's scale from the recorded (smoothed) channel."""
    u = u_m + (row[ek.R_CS_DISP] if row[ek.R_CS_ON] > 0 else 0.0) * v_m_s
    v = v_m_s
    if np.isfinite(dial_slope) and dial_slope > 0:
        scale = dial_slope * row[ek.P_PROJ]
        u, v = u / scale, v / scale
    return u, v


def _branch_elongation(
    row: FloatArray, x_rel_m: FloatArray, rate_hz: float, u_m: FloatArray
) -> FloatArray:
    """The Maxwell branch's elongation q/k₂ along the trace, from the measured history.

    q̇ = k₂·δ̇ − q/τ while taut and q̇ = −q/τ while slack: q/k₂ is the elongation
    max(δ, 0) high-passed with time constant τ (first order, discretised exactly for a
    step input).
    """
    delta = np.maximum(row[ek.P_PRELOAD] + x_rel_m - row[ek.P_PROJ] * u_m, 0.0)
    a = float(np.exp(-1.0 / (rate_hz * row[ek.R_VE_TAU])))
    # y_k = a·y_{k−1} + (δ_k − δ_{k−1}), from rest (y = 0 at the start).
    d = np.diff(delta, prepend=delta[0])
    out: FloatArray = lfilter([1.0], [1.0, -a], d)
    return out
