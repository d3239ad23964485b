"""The displacement gauge's gain error and offset.

Output transform: ``sim.effects.measure`` (one chain for the three gauge effects, in
physical order); equations: docs/effects.md.
"""

from __future__ import annotations

from sim.effects.info import EffectInfo, param

# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "dial_gauge_calibration", "measurement",
    "u_rec = (1 + gain_error)·u + offset_m",
    "residual ∝ u in every test; force unaffected",
    "DG",
    (
        param("gain_error", "1", 0.02, (-0.04, 0.04), (-0.5, 0.5), "GAIN",
              "relative gain error of the dial gauge", bounds=(-0.2, 0.2),
              why="a gauge mounted at an angle to the incline reads u/cos θ (15 % at 30°); "
                  "a lever gauge's arm angle and a mis-set scale add a few per cent"),
        # Not fitted: recordings count u from their rest reading, which removes it;
        # under multiple shooting a fitted offset would pose as a fibre length change.
        # Still drawn, so the check shows it is harmless.
        param("offset_m", "m", 0.0, (-2.0e-4, 2.0e-4), (-0.01, 0.01), "OFFSET",
              "reading at u = 0", fit=False, drawn=True),
    ),
    # Richer forms: curvature, backlash, creep: the u reading by position or time.
    richer=(("position", "u"), ("velocity", "u"), ("drift", "u")),
)
# fmt: on
