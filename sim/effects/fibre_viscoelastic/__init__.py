"""The fibre's viscoelasticity: a Maxwell branch beside the fibre's spring and damper.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.signal import lfilter

from sim.effects.info import EffectInfo, Measured, param

FloatArray = NDArray[np.float64]


def branch_elongation(row: FloatArray, measured: Measured) -> FloatArray:
    """The Maxwell branch's elongation q/k₂ along the trace, from the measured history.

    q̇ = k₂·δ̇ − q/τ while taut and q̇ = −q/τ while slack: q/k₂ is the elongation
    max(δ, 0) high-passed with time constant τ (first order, discretised exactly for a
    step input).
    """
    from sim.physics import layout  # the registry's columns (it imports this module)

    delta = np.maximum(
        row[layout.P_PRELOAD] + measured.x_rel_m - row[layout.P_PROJ] * measured.u_rec_m, 0.0
    )
    a = float(np.exp(-1.0 / (measured.rate_hz * row[layout.R_VE_TAU])))
    # y_k = a·y_{k−1} + (δ_k − δ_{k−1}), from rest (y = 0 at the start).
    d = np.diff(delta, prepend=delta[0])
    out: FloatArray = lfilter([1.0], [1.0, -a], d)
    return out


def _start_state(
    row: FloatArray, measured: Measured, starts: NDArray[np.int64], init: FloatArray
) -> None:
    from sim.physics import layout

    init[:, layout.I_HP] = branch_elongation(row, measured)[starts]


# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "fibre_viscoelastic", "physical",
    "standard linear solid: a Maxwell branch (spring k₂ in series with a dashpot "
    "c₂ = k₂·τ) parallel to the fibre's k, c; relaxes while slack",
    "force peaks and ringing damping change with drive rate; slow motion unaffected",
    "VE",
    (
        param("branch_stiffness_n_m", "N/m", 2.0e4, (3.0e3, 6.0e4), (0.0, 1.0e6), "K",
              "k₂, stiffness of the Maxwell branch (whole fibre)", log=True,
              bounds=(5.0e2, 2.0e5),
              why="a polymer-matrix fibre's dynamic stiffness exceeds its static one by a "
                  "few per cent up to several times (k is 34–94 kN/m)"),
        param("relaxation_time_s", "s", 0.03, (5.0e-3, 0.1), (1.0e-4, 10.0), "TAU",
              "τ = c₂/k₂, the branch's relaxation time", log=True, bounds=(5.0e-4, 1.0),
              why="faster than one 2 kHz sample it is plain damping; slower than the slowest "
                  "cycle (≈ 1–2.5 s) it is extra stiffness that k absorbs"),
    ),
    start_state=_start_state,
    # Richer forms: another relaxation branch or a nonlinear law: a filtered or curved tension.
    richer=(("strain", "u+F"), ("resonance", "u+F")),
    data_starts="sim.effects.fibre_viscoelastic.branch_starts:branch_starts",
)
# fmt: on
