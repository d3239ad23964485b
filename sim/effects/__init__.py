"""The unmodelled effects of STAND.md §5 as switchable augmentations of the baseline model.

Each effect is one module here (``fibre_viscoelastic.py``, ...: its ``INFO``).
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

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Lazy re-exports (PEP 562): importing one module of the package (``sim.effects.errors``,
# say) must not load the heavy ones (numba, scipy, pandas, h5py, ...) through it.
# A name here must not name both an object and a submodule (importing the submodule
# would rebind it to the module): sim.identify, whose ``diagnose`` is both, stays eager.
_EXPORTS = {
    "MeasurementNoise": "sim.effects.realism",
    "NoiseSpec": "sim.effects.realism",
    "add_measurement_noise": "sim.effects.realism",
    "draw_real_stand": "sim.effects.realism",
    "EFFECTS": "sim.effects.registry",
    "EffectError": "sim.effects.registry",
    "EffectInfo": "sim.effects.registry",
    "EffectSpec": "sim.effects.registry",
    "ParamInfo": "sim.effects.registry",
    "parse_effect": "sim.effects.registry",
    "parse_effects": "sim.effects.registry",
    "register": "sim.effects.registry",
    "unregister": "sim.effects.registry",
}

if TYPE_CHECKING:
    from sim.effects.realism import (
        MeasurementNoise,
        NoiseSpec,
        add_measurement_noise,
        draw_real_stand,
    )
    from sim.effects.registry import (
        EFFECTS,
        EffectError,
        EffectInfo,
        EffectSpec,
        ParamInfo,
        parse_effect,
        parse_effects,
        register,
        unregister,
    )


# The same PEP 562 hook in every package __init__ (drivers, sim, sim.effects, sim.hardware,
# recordings): a shared helper would have to live in the lowest layer, drivers.
def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'sim.effects' has no attribute {name!r}")
    if module == f"{__name__}.{name}":  # a submodule
        return importlib.import_module(module)
    return getattr(importlib.import_module(module), name)


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
    "register",
    "unregister",
]
