"""The best model of a stand: a saved diagnosis (``labstand diagnose --json``) read back.

The diagnosis' ``baseline_fit`` gives the fitted stiffness, damping and friction scales
(factors on the stand file's ``final`` parameter set), ``baseline_intervals`` (when the
diagnosis has them) their 95 % intervals, ``effects`` the named effects at their fitted
parameters, and ``ranking`` every candidate's own fit (the planner's rivals). A file that
is not such a result is bad input: one line, exit 2.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.errors import CommandError, ExitCode

if TYPE_CHECKING:
    from sim.effects import EffectSpec
    from sim.envelope import Spread

__all__ = ["SCALES", "FittedStand", "fitted_from_dict", "read_diagnosis"]

#: The baseline's fitted factors, in the order of ``Spread``'s.
SCALES = ("stiffness_scale", "damping_scale", "friction_scale")


@dataclass(frozen=True)
class FittedStand:
    """A diagnosis' model of the stand.

    Attributes
    ----------
    source
        Where it came from (the file), for messages.
    scales
        Fitted (stiffness, damping, friction) factors on the nominal stand.
    intervals
        Their 95 % intervals by ``SCALES`` name, where the diagnosis gives them.
    effects
        The named effects at their fitted parameters.
    rivals
        Every ranked candidate's own fit: effect name → its parameters.
    indistinguishable
        Named effect → the candidates the recordings could not tell from it.
    raw
        The diagnosis as read.
    """

    source: str
    scales: tuple[float, float, float]
    intervals: dict[str, tuple[float, float]]
    effects: tuple[EffectSpec, ...]
    rivals: dict[str, dict[str, float]] = field(default_factory=dict)
    indistinguishable: dict[str, list[str]] = field(default_factory=dict)
    raw: dict[str, Any] = field(default_factory=dict, repr=False)

    def spread(self) -> Spread:
        """The plausible range: the intervals where given, else ``FITTED_SPREAD`` about the fit."""
        from sim.envelope import FITTED_SPREAD, Spread

        if not all(name in self.intervals for name in SCALES):
            return FITTED_SPREAD.around(self.scales)
        ranges = [
            (min(self.intervals[name][0], value), max(self.intervals[name][1], value))
            for name, value in zip(SCALES, self.scales, strict=True)
        ]
        return Spread(ranges[0], ranges[1], ranges[2], self.scales)

    def describe(self) -> str:
        """The model in a few words."""
        k, c, f = self.scales
        effects = " + ".join(str(e) for e in self.effects) or "no effect"
        return f"the diagnosis {self.source} (k ×{k:.3g}, c ×{c:.3g}, friction ×{f:.3g}, {effects})"


def _bad(path: Path, what: str) -> CommandError:
    return CommandError(
        f"{path}: {what} (expected the output of `labstand diagnose --json`)", ExitCode.USAGE
    )


def _number(path: Path, key: str, value: Any, low: float = 0.0) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise _bad(path, f"{key} must be a finite number, got {value!r}")
    if value < low:
        raise _bad(path, f"{key} must be ≥ {low:g}, got {value:g}")
    return float(value)


def _params(path: Path, where: str, data: Any) -> dict[str, float]:
    if not isinstance(data, dict):
        raise _bad(path, f"{where} must be a table of numbers")
    return {str(k): _number(path, f"{where}.{k}", v, -math.inf) for k, v in data.items()}


def _effect(path: Path, name: Any, params: dict[str, float]) -> EffectSpec:
    from sim.effects import EFFECTS, EffectError, EffectSpec

    if not isinstance(name, str) or name not in EFFECTS:
        raise _bad(path, f"unknown effect {name!r}")
    spec = EffectSpec(name, params)
    try:
        spec.resolved()
    except EffectError as err:
        raise _bad(path, str(err)) from None
    return spec


def read_diagnosis(path: Path) -> FittedStand:
    """Read a saved diagnosis; CommandError (exit 2) on anything else."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CommandError(f"no such file: {path}", ExitCode.USAGE) from None
    except (OSError, UnicodeDecodeError) as err:
        raise CommandError(f"{path}: cannot read: {err}", ExitCode.USAGE) from None
    except json.JSONDecodeError as err:
        raise _bad(path, f"not JSON ({err})") from None
    return fitted_from_dict(data, path)


def fitted_from_dict(data: Any, path: Path) -> FittedStand:
    """A diagnosis' JSON (``Diagnosis.to_dict()``) as the stand's model; ``path`` names it."""
    if not isinstance(data, dict) or not isinstance(data.get("baseline_fit"), dict):
        raise _bad(path, "no baseline_fit")
    fit = data["baseline_fit"]
    scales = tuple(_number(path, f"baseline_fit.{n}", fit.get(n)) for n in SCALES)
    if scales[0] <= 0 or scales[1] <= 0:
        raise _bad(path, "the fitted stiffness and damping scales must be > 0")
    intervals: dict[str, tuple[float, float]] = {}
    for name, pair in (data.get("baseline_intervals") or {}).items():
        if name in SCALES and isinstance(pair, list) and len(pair) == 2:
            lo, hi = (_number(path, f"baseline_intervals.{name}", v) for v in pair)
            intervals[name] = (min(lo, hi), max(lo, hi))
    effects, indistinguishable = [], {}
    for item in data.get("effects") or []:
        if not isinstance(item, dict):
            raise _bad(path, "an entry of effects is not a table")
        params = _params(path, f"effects.{item.get('effect')}.params", item.get("params", {}))
        effects.append(_effect(path, item.get("effect"), params))
        indistinguishable[effects[-1].name] = [
            str(e) for e in item.get("indistinguishable_from") or []
        ]
    rivals = {}
    for item in data.get("ranking") or []:
        if isinstance(item, dict) and isinstance(item.get("params"), dict) and item["params"]:
            name = item.get("effect")
            rivals[str(name)] = dict(
                _effect(path, name, _params(path, "ranking", item["params"])).params
            )
    return FittedStand(
        str(path),
        (scales[0], scales[1], scales[2]),
        intervals,
        tuple(effects),
        rivals,
        indistinguishable,
        data,
    )
