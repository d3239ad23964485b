"""The stand's physics: parameters, configuration, the model, paper situations, identification.

``sim.model.Model`` is the one front door to the model (runs, batches, segment runs,
streams); ``sim.identify`` is the sim-to-real gap diagnosis on arrays.

Exceptions::

    ValueError
     ├── ConfigError        a stand file that cannot be used (names file and key)
     └── SimulationError    unusable model input (non-finite, too short, bad effect)
"""

from sim.config import ConfigError, ParameterSet, StandConfig, default_config, load_config
from sim.errors import SimulationError
from sim.model import BatchResult, Model, ModelRun, SimResult
from sim.params import FrictionTable, StandParams

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
