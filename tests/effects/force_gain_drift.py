"""A gauge effect written outside the package: a force gauge whose gain drifts in time.

The force gauge's bridge is fed by an excitation supply that sags (or a warming
amplifier's gain creeps) after the gauge was zeroed and calibrated at the recording's
start: the reading's gain grows linearly with the time t since then,

    F_rec = (1 + r·t)·F,    so back:  F = F_rec / (1 + r·t),

and the displacement channel is unaffected. The force residual grows with t·F: small in
the first second, a per cent of the force after a few.

This one file is all it needs: its parameters (``INFO``), ``record`` (what the gauge
shows of the true u and F) and ``invert`` (the true channels from the recorded ones, for
restarts from measured states), plain numpy. ``sim.effects.register(INFO)`` adds it to
the end of the model's gauge chain (``sim.physics.gauges``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.effects.info import EffectInfo, param

FloatArray = NDArray[np.float64]


def record(
    values: FloatArray, t_s: FloatArray, u_m: FloatArray, force_n: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """(u, (1 + r·t)·F): the recorded channels from the true ones."""
    (drift,) = values
    return u_m, (1.0 + drift * t_s) * force_n


def invert(
    values: FloatArray, t_s: FloatArray, u_m: FloatArray, v_m_s: FloatArray, force_n: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(u, v, F_rec/(1 + r·t)): the true channels from the recorded ones."""
    (drift,) = values
    return u_m, v_m_s, force_n / (1.0 + drift * t_s)


# fmt: off
INFO = EffectInfo(
    "force_gain_drift", "measurement",
    "the force gauge's gain drifts linearly from its calibration at the recording's start: "
    "F_rec = (1 + r·t)·F",
    "force residual ∝ t·F, growing through each recording; displacement unaffected",
    "GD",
    (
        param("drift_per_s", "1/s", 4.0e-3, (2.0e-3, 8.0e-3), (-0.05, 0.05), "RATE",
              "r, the gain's relative change per second", bounds=(-0.02, 0.02),
              why="a sagging bridge supply or a warming amplifier: a sound one drifts "
                  "0.01 %/s, a failing one a per cent in a few seconds"),
    ),
    record=record,
    invert=invert,
)
# fmt: on
