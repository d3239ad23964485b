"""Extra guide friction from the fibre's lateral pull on the weight.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

from sim.effects.info import EffectInfo, param

# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "side_load_friction", "physical",
    "the lateral pull T·sin β presses the weight on the guide wall: extra friction "
    "μ_s·T·sin β (T the weight-side tension), zero while slack",
    "friction that grows with tension and vanishes when slack",
    "SL",
    (
        param("friction_coeff", "1", 0.1, (0.03, 0.3), (0.0, 2.0), "MU",
              "μ_s, friction coefficient of the guide wall", bounds=(0.0, 0.8),
              why="steel or aluminium on a dry guide wall: up to 0.6–0.8"),
    ),
    # Richer forms: a friction growing with another power of the tension, a speed
    # dependence. (Not the fibre's law beyond linear, "strain": a tension the fibre
    # lacks is no friction on the weight; behind the other stand's light side load it
    # set aside the string modes, a branch and a pulley's inertia alike.)
    richer=(("friction", "u+F"), ("velocity", "u+F")),
)
# fmt: on
