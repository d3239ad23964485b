"""Writing simulated runs to files, chosen by the output's suffix."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from drivers.signals import DriveProfile
from labstand.errors import CommandError, ExitCode
from recordings.convert import write_streams
from recordings.csvio import write_csv
from recordings.formats import suffixes
from recordings.schema import COMMAND_DTYPE, GAUGES_DTYPE, Backend, make_metadata
from sim.config import StandConfig
from sim.results import SimResult

#: The simulation's four columns as CSV, or a full recording through a streaming writer.
SUFFIXES = (".csv", *suffixes("write"))


def write_simulation(
    path: Path,
    result: SimResult,
    config: StandConfig,
    params: str,
    profile: DriveProfile,
    situation: str | None,
    mass_kg: float | None = None,
    **extra: Any,
) -> None:
    """Write a simulated run; the suffix picks the format.

    CSV holds the four columns; MCAP and HDF5 a full recording (backend ``simulate``):
    the gauges stream is the model's output with ``seq`` 0..N−1 and ``t_ns`` = i·(1/rate),
    the command stream is the drive position x.
    """
    suffix = path.suffix.lower()
    if suffix == ".csv":
        write_csv(path, result.t_s, result.x_m * 1e3, result.u_m * 1e3, result.force_n)
        return
    if suffix not in SUFFIXES:
        raise CommandError(
            f"{path}: unknown output format {suffix!r}; use one of {', '.join(SUFFIXES)}",
            ExitCode.USAGE,
        )
    rate = config.sample_rate_hz
    n = result.t_s.shape[0]
    index = np.arange(n, dtype=np.int64)
    gauges = np.zeros(n, dtype=GAUGES_DTYPE)
    gauges["seq"] = index
    gauges["t_ns"] = index * round(1e9 / rate)
    gauges["x_mm"] = result.x_m * 1e3
    gauges["u_mm"] = result.u_m * 1e3
    gauges["force_n"] = result.force_n
    command = np.empty(n, dtype=COMMAND_DTYPE)
    command["t_ns"] = gauges["t_ns"]
    command["x_cmd_mm"] = gauges["x_mm"]
    what = f"situation {situation}" if situation else str(profile.spec.shape)
    from labstand.commands.common import config_with_mass

    stand = config.to_dict() if mass_kg is None else config_with_mass(config, mass_kg)
    metadata = make_metadata(
        stand,  # its default weight is the simulated one, as `run` stores it
        Backend.SIMULATE,
        sample_rate_hz=rate,
        signal={**profile.spec.to_dict(), "situation": situation},
        operator_note=f"labstand simulate: {what}, parameter set {params!r}",
        **extra,  # operator, sample, tags
    )
    end_ns = int(gauges["t_ns"][-1])
    events = [(0, "start", what), (end_ns, "stop", "end of simulation")]
    write_streams(path, metadata, gauges, command, events=events)
