"""The fibre's viscoelasticity: a Maxwell branch beside the fibre's spring and damper.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.effects.info import EffectInfo, Measured, param

FloatArray = NDArray[np.float64]


def branch_elongation(row: FloatArray, measured: Measured) -> FloatArray:
    """The Maxwell branch's elongation q/k₂ along the trace, from the measured history.

    q̇ = k₂·δ̇ − q/τ while taut and q̇ = −q/τ while slack, integrated as the model does
    (``sim.physics.integrator._step``): the drive moves at a constant rate over each
    sample step, the fibre is taut while δ > 0 *and* its tension law k·δ + c·δ̇ + q > 0
    (``sim.physics.fibre._set_taut``), and a step is split where it switches. Measured:
    judged on δ alone, a fast unloading (where q and c·δ̇ take the law to zero while δ
    is still positive) went on loading the branch, and every restart after a slack
    episode — where segments restart — began with the wrong branch force; on ``make
    demo``'s recordings the true model's restarted runs missed by 3–6× the noise (open
    loop 1.0–1.3×) and k₂ came out 0.3 % low. Taken as a step of δ per sample instead
    of a ramp, the history came out h/2τ too large (0.8 % at τ = 30 ms); a switch
    placed at a sample instead of inside it left up to k₂·Δδ (2 N at 0.2 m/s).
    """
    from sim.effects.fibre_viscoelastic.history import branch_history  # numba, when run
    from sim.physics import layout  # the registry's columns (it imports this module)

    n = row[layout.P_PROJ]
    delta = row[layout.P_PRELOAD] + measured.x_rel_m - n * measured.u_m
    drive_rate = np.diff(measured.x_rel_m, prepend=measured.x_rel_m[0]) * measured.rate_hz
    return branch_history(
        delta, drive_rate, n * measured.v_m_s, measured.rate_hz * row[layout.R_VE_TAU],
        row[layout.P_STIFF], row[layout.P_DAMP], row[layout.R_VE_K],
    )  # fmt: skip


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
    # Richer forms: another relaxation branch, a nonlinear law, a filtered tension.
    richer=(("relaxation", "u+F"), ("strain", "u+F"), ("resonance", "u+F")),
    data_starts="sim.effects.fibre_viscoelastic.branch_starts:branch_starts",
)
# fmt: on
