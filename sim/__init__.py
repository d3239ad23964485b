"""The stand's physics: parameters, configuration, the baseline model, paper situations.

Exceptions::

    ValueError
     ├── ConfigError        a stand file that cannot be used (names file and key)
     └── SimulationError    unusable model input (non-finite, too short)
"""

from sim.config import ConfigError, ParameterSet, StandConfig, default_config, load_config
from sim.model import BatchResult, SimResult, SimulationError, simulate, simulate_batch
from sim.params import FrictionTable, StandParams

__all__ = [
    "BatchResult",
    "ConfigError",
    "FrictionTable",
    "ParameterSet",
    "SimResult",
    "SimulationError",
    "StandConfig",
    "StandParams",
    "default_config",
    "load_config",
    "simulate",
    "simulate_batch",
]
