"""The pulley's own rotation: inertia and elasto-plastic bearing friction.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

from sim.effects.info import EffectError, EffectInfo, param
from sim.params import StandParams


def _check_stand(stand: StandParams) -> None:
    if stand.drive_span_m <= 0:
        raise EffectError("pulley_inertia_friction needs a positive drive span ℓ₁")


# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "pulley_inertia_friction", "physical",
    "pulley rotation (inertia J) with elasto-plastic bearing friction "
    "(M₀/r + μ_L·hub load); the fibre splits into drive- and weight-side segments",
    "force hysteresis between pull and return, spikes at drive accelerations",
    "PI",
    (
        param("inertia_kg_m2", "kg·m²", 1.1e-4, (3.0e-5, 3.0e-4), (1.0e-6, 1.0e-2), "J",
              "pulley moment of inertia", log=True, bounds=(1.0e-5, 2.0e-3),
              why="an 80 mm aluminium disc 5–10 mm thick has 6e-5–1.1e-4 kg·m²; steel, a "
                  "hub and a shaft raise it to about 1e-3"),
        param("bearing_torque_n_m", "N·m", 0.01, (0.002, 0.03), (0.0, 0.5), "TORQUE",
              "load-independent bearing friction torque M₀", bounds=(0.0, 0.1),
              why="a clean ball bearing has about 1e-3 N·m; seals, a plain bush or dirt raise "
                  "it to 0.05–0.1 N·m"),
        param("load_coeff", "1", 0.005, (0.0, 0.02), (0.0, 0.2), "LOAD",
              "bearing friction at the rim per newton of hub load (T₁ + T₂)·sin(φ/2)",
              bounds=(0.0, 0.05),
              why="bore friction μ 0.001–0.2 (rolling to plain) times bore/rim radius ≈ 0.25"),
        param("presliding_m", "m", 1.0e-5, (2.0e-6, 5.0e-5), (1.0e-7, 1.0e-3), "PRESLIDE",
              "rim displacement before the bearing slides (at rest load)", fit=False, log=True),
    ),
    check_stand=_check_stand,
    # Richer forms: another bearing law, a compliant rim: speed shapes, a mode.
    richer=(("velocity", "u+F"), ("resonance", "u+F")),
)
# fmt: on
