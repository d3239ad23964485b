"""The unmodelled effects of STAND.md §5 as switchable augmentations of the baseline model.

``EFFECTS`` lists the nine effects with their parameters (units, plausible and admissible
ranges, defaults); ``simulate_augmented`` runs the baseline plus any combination of them
(``simulate_augmented_batch`` many at once, ``AugmentedStream`` block by block);
``sim.effects.realism`` adds measurement noise and draws "real" stands. Equations and
signatures: docs/effects.md.

Exceptions::

    ValueError
     └── SimulationError        (sim.model)
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
from sim.effects.simulator import (
    AugmentedBatchResult,
    AugmentedResult,
    AugmentedStream,
    augmented_row,
    param_column,
    simulate_augmented,
    simulate_augmented_batch,
    simulate_augmented_rows,
)

__all__ = [
    "EFFECTS",
    "AugmentedBatchResult",
    "AugmentedResult",
    "AugmentedStream",
    "EffectError",
    "EffectInfo",
    "EffectSpec",
    "MeasurementNoise",
    "NoiseSpec",
    "ParamInfo",
    "add_measurement_noise",
    "augmented_row",
    "draw_real_stand",
    "param_column",
    "parse_effect",
    "parse_effects",
    "simulate_augmented",
    "simulate_augmented_batch",
    "simulate_augmented_rows",
]

from sim.effects.stand_plugin import register_all as _register_with_the_simulated_stand

_register_with_the_simulated_stand()
