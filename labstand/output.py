"""Writing simulated runs to files, chosen by the output's suffix."""

from __future__ import annotations

from pathlib import Path

from drivers.signals import DriveProfile
from labstand.errors import CommandError, ExitCode
from recordings.csvio import write_csv
from sim.config import StandConfig
from sim.model import SimResult

SUFFIXES = (".csv",)


def write_simulation(
    path: Path,
    result: SimResult,
    config: StandConfig,
    params: str,
    profile: DriveProfile,
    situation: str | None,
) -> None:
    """Write a simulated run; the suffix picks the format."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        write_csv(path, result.t_s, result.x_m * 1e3, result.u_m * 1e3, result.force_n)
        return
    raise CommandError(
        f"{path}: unknown output format {suffix!r}; use one of {', '.join(SUFFIXES)}",
        ExitCode.USAGE,
    )
