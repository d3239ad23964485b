"""A gauge channel sampled late (or early) against the drive channel.

Output transform: ``sim.effects.measure`` (one chain for the three gauge effects, in
physical order); equations: docs/effects.md.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.effects import kernel as ek
from sim.effects.info import EffectInfo, param

FloatArray = NDArray[np.float64]


def _true_channels(
    row: FloatArray, u_m: FloatArray, v_m_s: FloatArray
) -> tuple[FloatArray, FloatArray]:
    # A displacement channel recorded Δt late shows the true u of Δt earlier, so the
    # true u now is u_rec(t + Δt) ≈ u_rec + Δt·v.
    return u_m + row[ek.R_CS_DISP] * v_m_s, v_m_s


# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "channel_time_skew", "measurement",
    "a channel is sampled Δt late (Δt < 0: early) against the drive channel",
    "residual ∝ the channel's derivative; cross-correlation peak off zero",
    ek.R_CS_ON,
    (
        param("force_skew_s", "s", 1.0e-3, (-3.0e-3, 3.0e-3), (-0.05, 0.05), ek.R_CS_FORCE,
              "delay of the force channel", log=True, bounds=(-0.025, 0.025),
              why="separate buffers, serial latency and filter delays: up to 50 samples "
                  "(25 ms) either way at 2 kHz"),
        param("displacement_skew_s", "s", 0.0, (-3.0e-3, 3.0e-3), (-0.05, 0.05), ek.R_CS_DISP,
              "delay of the displacement channel", log=True, bounds=(-0.025, 0.025),
              why="as the force channel's"),
    ),
    true_channels=_true_channels,
)
# fmt: on
