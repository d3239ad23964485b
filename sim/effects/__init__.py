"""The unmodelled effects of STAND.md §5 as switchable augmentations of the baseline model.

``EFFECTS`` lists the nine effects with their parameters (units, plausible and admissible
ranges, defaults); ``sim.model.Model(stand, effects)`` runs the baseline with any
combination of them; ``sim.effects.realism`` adds measurement noise and draws "real"
stands. Equations and signatures: docs/effects.md. Importing this package registers
nothing anywhere: the registry is the ``EFFECTS`` dict.

Exceptions::

    ValueError
     └── SimulationError        (sim.errors)
          └── EffectError       unknown effect or parameter, value out of range
"""

from sim.effects.realism import MeasurementNoise, NoiseSpec, add_measurement_noise, draw_real_stand
from sim.effects.registry import (
    EFFECTS,
    EffectError,
    EffectInfo,
    EffectSpec,
    ParamInfo,
    parse_effect,
    parse_effects,
)

__all__ = [
    "EFFECTS",
    "EffectError",
    "EffectInfo",
    "EffectSpec",
    "MeasurementNoise",
    "NoiseSpec",
    "ParamInfo",
    "add_measurement_noise",
    "draw_real_stand",
    "parse_effect",
    "parse_effects",
]
