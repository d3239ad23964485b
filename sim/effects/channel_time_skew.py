"""A gauge channel sampled late (or early) against the drive channel.

Output transform: ``sim.effects.measure`` (one chain for the three gauge effects, in
physical order); equations: docs/effects.md.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.effects.info import EffectInfo, param

FloatArray = NDArray[np.float64]


def _true_channels(
    row: FloatArray, rate_hz: float, u_m: FloatArray, v_m_s: FloatArray, force_n: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    # A channel recorded Δt late shows now the true value of Δt earlier: the true value
    # now is the recorded one Δt later, read between samples. (The first-order
    # u_rec + Δt·v missed by ½·a·Δt² in a light weight's bounce: 0.9 mm at 6 ms and
    # 50 m/s², and kept v and the force unshifted; the true model restarted so predicted
    # a quick light-weight trace's force with an NRMSE of 0.9.)
    def shifted(series: FloatArray, delay_s: float) -> FloatArray:
        if delay_s == 0.0:
            return series
        at = np.arange(series.size) + delay_s * rate_hz
        return np.asarray(np.interp(at, np.arange(series.size), series), dtype=np.float64)

    from sim.physics import layout  # the registry's columns (it imports this module)

    displacement, force = row[layout.R_CS_DISP], row[layout.R_CS_FORCE]
    return shifted(u_m, displacement), shifted(v_m_s, displacement), shifted(force_n, force)


# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "channel_time_skew", "measurement",
    "a channel is sampled Δt late (Δt < 0: early) against the drive channel",
    "residual ∝ the channel's derivative; cross-correlation peak off zero",
    "CS",
    (
        param("force_skew_s", "s", 1.0e-3, (-3.0e-3, 3.0e-3), (-0.05, 0.05), "FORCE",
              "delay of the force channel", log=True, bounds=(-0.025, 0.025),
              why="separate buffers, serial latency and filter delays: up to 50 samples "
                  "(25 ms) either way at 2 kHz"),
        param("displacement_skew_s", "s", 0.0, (-3.0e-3, 3.0e-3), (-0.05, 0.05), "DISP",
              "delay of the displacement channel", log=True, bounds=(-0.025, 0.025),
              why="as the force channel's"),
    ),
    true_channels=_true_channels,
    # Richer forms: a delay that depends on frequency: a filter on the force reading.
    richer=(("resonance", "F"),),
    leads=("force_skew_s", "displacement_skew_s"),
)
# fmt: on
