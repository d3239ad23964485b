"""Segment start states from measurements, per kernel row (private: ``sim.model`` uses it).

A segment of a multiple-shooting run restarts from the state the gauges measured. What
the dial gauge reads is scaled by its gain G against the drive encoder, which the
recording itself shows (``Restarts.dial_slope``): every row restarts from u_rec/G, so a
gain error never becomes a wrong elongation (a wrong force) — it stays in the u channel,
where a candidate's dial gauge model maps the true u to the reading. Gauge effects with
an inverse (``EffectInfo.true_channels``: a skewed channel; ``EffectInfo.invert``: one
added with ``register``) map the recorded channels to the true ones first
(``sim.physics.gauges.true_channels``); effects with measurable states set them
(``EffectInfo.start_state``: the Maxwell branch, the pulley seat). The other effects'
states are set inside the kernel (``kernel.measured_state``) or carried between segments.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from sim.effects.fibre_pulley_jump import recorded_seat
from sim.effects.info import Measured
from sim.effects.registry import EFFECTS
from sim.physics import gauges, layout

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = ["StartStates", "start_states"]


class StartStates(NamedTuple):
    """What the segment runs of a batch start from."""

    #: (sets, segments, layout.N_INIT): each segment's measured start (columns layout.I_*).
    init: FloatArray
    #: (sets, samples): each row's pulley-seat offset at every sample, as the recorded
    #: slack episodes put it (``fibre_pulley_jump.recorded_seat``; 0 where the row has no
    #: pulley jump), or (sets, 0) if no row has one (every run's seat is the model's).
    seats: FloatArray


def start_states(
    rows: FloatArray,
    x_rel_m: FloatArray,
    rate_hz: float,
    starts: IntArray,
    u_m: FloatArray,
    v_m_s: FloatArray,
    force_n: FloatArray,
    dial_slope: float = float("nan"),
) -> StartStates:
    """Measured start states for augmented kernel rows, and their recorded seats.

    ``u_m``, ``v_m_s``, ``force_n``: the recorded channels (smoothed) at every sample;
    ``dial_slope``: du_rec/dx at constant force (NaN: take the gauge's scale as 1).
    """
    rows2 = np.atleast_2d(rows)
    init = np.zeros((rows2.shape[0], starts.size, layout.N_INIT))
    jumps = rows2[:, layout.R_PJ_ON] > 0
    seats = np.zeros((rows2.shape[0], x_rel_m.size if np.any(jumps) else 0))
    # Rows whose channel transforms agree share their true channels (every row of a fit
    # but a skew's): computed once per batch, not once per row over the whole trace.
    channels: dict[bytes, tuple[FloatArray, FloatArray, FloatArray, FloatArray]] = {}
    for b, row in enumerate(rows2):
        on = [info for info in EFFECTS.values() if row[info.flag_column] > 0]
        key = gauges.transform_key(row, on)
        if key not in channels:
            u, v, force = gauges.true_channels(row, on, rate_hz, u_m, v_m_s, force_n, dial_slope)
            channels[key] = (u, v, force, np.gradient(force, 1.0 / rate_hz)[starts])
        u, v, force, rate = channels[key]
        init[b, :, layout.I_U] = u[starts]
        init[b, :, layout.I_V] = v[starts]
        init[b, :, layout.I_F] = force[starts]
        init[b, :, layout.I_FRATE] = rate
        measured = Measured(x_rel_m, rate_hz, u_m, u, v, force)
        for info in on:
            if info.start_state is not None:
                info.start_state(row, measured, starts, init[b])
        if jumps[b]:
            seats[b] = recorded_seat(row, measured)
    return StartStates(init, seats)
