"""Which stand and parameters a recording is replayed with."""

from __future__ import annotations

import logging
from pathlib import Path

from labstand.errors import CommandError, ExitCode
from recordings import Recording
from sim.config import ConfigError, StandConfig, config_from_dict, load_config
from sim.params import StandParams

log = logging.getLogger(__name__)


def stand_of(recording: Recording, stand_file: Path | None) -> StandConfig:
    """The stand file if given, else the configuration stored in the recording."""
    if stand_file is not None:
        return load_config(stand_file)
    try:
        return config_from_dict(recording.metadata.stand_config, f"{recording.path} (stored stand)")
    except ConfigError as err:
        raise CommandError(f"{err}; give the stand with --stand FILE", ExitCode.USAGE) from None


def mass_source(recording: Recording, stand_file: Path | None, mass_kg: float | None) -> str:
    """Where the mass ``params_for`` uses comes from, for the command's output."""
    if mass_kg is not None:
        return "--mass-kg"
    if stand_file is not None:
        return f"default weight of {stand_file}"
    return "stored in the recording"


def params_for(
    recording: Recording, stand_file: Path | None, params: str, mass_kg: float | None
) -> tuple[StandParams, str]:
    """Model parameters for a replay: a named set, or a stand FILE whose 'final' set is used.

    The mass is --mass-kg, else the default weight of the stand file if one is given, else
    the weight stored in the recording's stand (``run --mass-kg``, ``import --mass-kg``);
    ``mass_source`` says which.
    """
    config = stand_of(recording, stand_file)
    name = params
    candidate = Path(params)
    if candidate.suffix == ".toml" or candidate.is_file():
        overlay = load_config(candidate)
        mass = mass_kg if mass_kg is not None else config.default_mass_kg
        return overlay.stand_params("final", mass), f"{candidate} (final)"
    return config.stand_params(name, mass_kg), name
