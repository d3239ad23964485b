"""The stand's physics: parameters, configuration, the model, paper situations, identification.

``sim.model.Model`` is the one front door to the model (runs, batches, segment runs,
streams); ``sim.identify`` is the sim-to-real gap diagnosis on arrays.

Exceptions::

    ValueError
     ├── ConfigError        a stand file that cannot be used (names file and key)
     └── SimulationError    unusable model input (non-finite, too short, bad effect)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Lazy re-exports (PEP 562): importing one module of the package (``sim.errors``,
# say) must not load the heavy ones (numba, scipy, pandas, h5py, ...) through it.
# A name here must not name both an object and a submodule (importing the submodule
# would rebind it to the module): sim.identify, whose ``diagnose`` is both, stays eager.
_EXPORTS = {
    "ConfigError": "sim.config",
    "ParameterSet": "sim.config",
    "StandConfig": "sim.config",
    "default_config": "sim.config",
    "load_config": "sim.config",
    "SimulationError": "sim.errors",
    "BatchResult": "sim.model",
    "Model": "sim.model",
    "ModelRun": "sim.model",
    "SimResult": "sim.model",
    "FrictionTable": "sim.params",
    "StandParams": "sim.params",
}

if TYPE_CHECKING:
    from sim.config import ConfigError, ParameterSet, StandConfig, default_config, load_config
    from sim.errors import SimulationError
    from sim.model import BatchResult, Model, ModelRun, SimResult
    from sim.params import FrictionTable, StandParams


# The same PEP 562 hook in every package __init__ (drivers, sim, sim.effects, sim.hardware,
# recordings): a shared helper would have to live in the lowest layer, drivers.
def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'sim' has no attribute {name!r}")
    if module == f"{__name__}.{name}":  # a submodule
        return importlib.import_module(module)
    return getattr(importlib.import_module(module), name)


__all__ = [
    "BatchResult",
    "ConfigError",
    "FrictionTable",
    "Model",
    "ModelRun",
    "ParameterSet",
    "SimResult",
    "SimulationError",
    "StandConfig",
    "StandParams",
    "default_config",
    "load_config",
]
