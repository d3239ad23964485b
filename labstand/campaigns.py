"""Campaign manifests (``labstand diagnose --campaigns FILE``) and the job that diagnoses one.

A manifest is TOML, one table per campaign::

    [campaign.light]
    recordings = ["light/quick.mcap", "light/slow.mcap"]   # relative to the manifest
    mass_kg = 3.096
    stand = "stands/lab2.toml"        # optional: the nominal stand (default: the paper's)
    truth = "fibre_viscoelastic"      # optional: the known answer, for the confusion matrix

The manifest is checked here, whole, before anything runs (a malformed one is bad input,
exit 2); a campaign whose recordings cannot be read or diagnosed fails alone, on its
worker, and is reported with its error.
"""

from __future__ import annotations

import dataclasses
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from labstand.errors import CommandError, ExitCode, describe_os_error
from recordings import open_recording
from sim.config import load_config
from sim.identify import DiagnosisInputError, Trace, diagnose, make_trace
from sim.identify.traces import MIN_DURATION_S

_KEYS = {"recordings", "mass_kg", "stand", "truth"}


@dataclass(frozen=True)
class Campaign:
    """One campaign of a manifest: recordings of one stand at one weight mass."""

    name: str
    recordings: tuple[Path, ...]
    mass_kg: float | None  # None: the mass stored in each recording
    stand: Path | None = None
    truth: str | None = None


def load_manifest(path: Path) -> list[Campaign]:
    """The manifest's campaigns in file order (CommandError, exit 2, naming what is wrong)."""
    try:
        data = tomllib.loads(path.read_text())
    except OSError as err:
        text, _ = describe_os_error(err)  # "no such file: X", "X: is a folder, not a file"
        raise CommandError(f"cannot read the manifest: {text}", ExitCode.USAGE) from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise CommandError(f"{path}: not TOML: {err}", ExitCode.USAGE) from None
    tables = data.get("campaign")
    if not isinstance(tables, dict) or not tables:
        raise CommandError(f"{path}: no [campaign.NAME] tables", ExitCode.USAGE)
    base = path.parent
    return [_campaign(path, base, name, table) for name, table in tables.items()]


def _campaign(path: Path, base: Path, name: str, table: object) -> Campaign:
    where = f"{path}: [campaign.{name}]"
    if not isinstance(table, dict):
        raise CommandError(f"{where} is not a table", ExitCode.USAGE)
    unknown = set(table) - _KEYS
    if unknown:
        raise CommandError(
            f"{where}: unknown key(s) {', '.join(sorted(unknown))} "
            f"(known: {', '.join(sorted(_KEYS))})",
            ExitCode.USAGE,
        )
    recs = table.get("recordings")
    if not isinstance(recs, list) or not recs or not all(isinstance(r, str) for r in recs):
        raise CommandError(f"{where}: recordings must be a non-empty list of paths", ExitCode.USAGE)
    mass = table.get("mass_kg")
    if mass is not None and (
        isinstance(mass, bool) or not isinstance(mass, int | float) or not mass > 0
    ):
        raise CommandError(f"{where}: mass_kg must be a number > 0, got {mass!r}", ExitCode.USAGE)
    stand = table.get("stand")
    truth = table.get("truth")
    for key, value in (("stand", stand), ("truth", truth)):
        if value is not None and not isinstance(value, str):
            raise CommandError(f"{where}: {key} must be a string", ExitCode.USAGE)
    return Campaign(
        name=name,
        recordings=tuple((base / r).resolve() for r in recs),
        mass_kg=None if mass is None else float(mass),
        stand=None if stand is None else (base / stand).resolve(),
        truth=truth,
    )


def trace_of(name: str, frame: pd.DataFrame, mass_kg: float) -> Trace:
    """A recording's frame (t_s index, x_mm, u_mm, F_N) as a diagnosis trace (SI units)."""
    for column in ("x_mm", "u_mm", "F_N"):
        if column not in frame.columns:
            raise DiagnosisInputError(f"{name}: the recording has no {column} channel")
    # times from the first sample, via whole ns: a recording cut at t = 1 … 2 s spans
    # exactly 1 s, not 1 s less a rounding error that the fit's "≥ 1 s" would refuse
    t_ns = np.rint(np.asarray(frame.index, dtype=np.float64) * 1e9).astype(np.int64)
    span_s = (int(t_ns[-1]) - int(t_ns[0])) / 1e9 if len(t_ns) else 0.0
    if span_s < MIN_DURATION_S:
        raise DiagnosisInputError(
            f"{name}: spans {span_s:.4g} s, too short to fit (need ≥ {MIN_DURATION_S:g} s)"
        )
    return make_trace(
        name,
        (t_ns - t_ns[0]) / 1e9,
        frame["x_mm"].to_numpy(dtype=np.float64) * 1e-3,
        frame["u_mm"].to_numpy(dtype=np.float64) * 1e-3,
        frame["F_N"].to_numpy(dtype=np.float64),
        mass_kg,
    )


def unique_names(traces: list[Trace]) -> list[Trace]:
    """Traces renamed ``i:name`` when two recordings share a file name."""
    names = [t.name for t in traces]
    if len(set(names)) == len(names):
        return traces
    return [dataclasses.replace(t, name=f"{i}:{t.name}") for i, t in enumerate(traces)]


def diagnose_campaign(campaign: Campaign) -> dict[str, Any]:
    """The job: read a campaign's recordings and diagnose them (runs on a worker).

    Returns the diagnosis as JSON (``Diagnosis.to_dict``) with the campaign's ``name``,
    ``truth`` and ``recordings``; only this small dict travels back, not the arrays.
    """
    nominal = load_config(campaign.stand).stand_params("final", campaign.mass_kg)
    traces, masses = [], {}
    for path in campaign.recordings:
        rec = open_recording(path)
        mass = campaign.mass_kg
        if mass is None:  # as a single `diagnose` does: the weight the recording was made with
            mass, _ = stored_mass(path, rec.metadata.stand_config)
        masses[str(path)] = mass
        traces.append(trace_of(path.name, rec.frame(), mass))
    result = diagnose(unique_names(traces), nominal)
    return {
        "name": campaign.name,
        "truth": campaign.truth,
        "recordings": [str(p) for p in campaign.recordings],
        "mass_kg": campaign.mass_kg if campaign.mass_kg is not None else masses,
        **result.to_dict(),
    }


def stored_mass(path: Path, stored: object) -> tuple[float, str]:
    """The weight stored in a recording (its stand's default weight), and where from."""
    from sim.config import config_from_dict

    try:
        mass = config_from_dict(stored, str(path)).default_mass_kg  # type: ignore[arg-type]
    except (ValueError, TypeError):  # sim.config.ConfigError is a ValueError
        fallback = load_config(None).default_mass_kg
        return fallback, "the paper stand's default weight (the stored stand is unreadable)"
    return mass, "stored in the recording"
