"""The registry of effects: ``EFFECTS`` by name, and what a user writes to switch one on.

Each effect is one module under ``sim/effects/`` (its ``INFO``: parameters with units,
ranges and why, and its hooks into the model); this module lists them in ``EFFECTS``,
explicitly — importing an effect module registers nothing. An effect written outside the
kernel (a tenth, say) is one module too, added with ``register`` (see
docs/architecture.md). ``EffectSpec`` names an effect and the parameters that differ from
its defaults; ``parse_effect`` reads ``NAME[:param=value,...]``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace

from sim.effects.info import EffectError, EffectInfo, ParamInfo
from sim.physics import added, layout

__all__ = [
    "EFFECTS",
    "EffectError",
    "EffectInfo",
    "EffectSpec",
    "ParamInfo",
    "effect_info",
    "parse_effect",
    "parse_effects",
    "register",
    "unregister",
]


@dataclass(frozen=True)
class EffectSpec:
    """An effect switched on, with the parameters that differ from its defaults."""

    name: str
    params: Mapping[str, float] = field(default_factory=dict)

    def resolved(self) -> dict[str, float]:
        """All parameters (defaults filled in), checked against the admissible ranges."""
        info = effect_info(self.name)
        values = info.defaults()
        for key, raw in self.params.items():
            p = info.param(key)
            value = float(raw)
            if not (math.isfinite(value) and p.minimum <= value <= p.maximum):
                unit = "" if p.unit == "1" else f" {p.unit}"  # dimensionless: no unit
                raise EffectError(
                    f"{self.name}: {key} = {value:g}{unit} is outside its admissible range "
                    f"[{p.minimum:g}, {p.maximum:g}]{unit}"
                )
            if p.integer and value != round(value):
                raise EffectError(f"{self.name}: {key} = {value:g} must be a whole number")
            values[key] = value
        return values

    def __str__(self) -> str:
        args = ",".join(f"{k}={v:g}" for k, v in self.params.items())
        return f"{self.name}:{args}" if args else self.name


#: The effects by name: the nine of STAND.md §5, in its order (``sim.effects.builtin``)
#: with their row columns, then any ``register``ed.
EFFECTS: dict[str, EffectInfo] = {info.name: info for info in layout.PLACED}


def effect_info(name: str) -> EffectInfo:
    """An effect by name (EffectError naming the known ones if unknown)."""
    try:
        return EFFECTS[name]
    except KeyError:
        raise EffectError(f"unknown effect {name!r}; known: {', '.join(EFFECTS)}") from None


def parse_effect(text: str) -> EffectSpec:
    """``NAME[:param=value,...]`` → a checked EffectSpec (EffectError, one line, if bad)."""
    name, _, rest = text.strip().partition(":")
    info = effect_info(name.strip())
    params: dict[str, float] = {}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, raw = item.partition("=")
        key = key.strip()
        if not eq:
            raise EffectError(f"{info.name}: expected param=value, got {item!r}")
        unit = info.param(key).unit
        if key in params:
            raise EffectError(f"{info.name}: {key} given twice")
        try:
            params[key] = float(raw)
        except ValueError:
            raise EffectError(
                f"{info.name}: {key} must be a number ({unit}), got {raw!r}"
            ) from None
    spec = EffectSpec(info.name, params)
    spec.resolved()
    return spec


def parse_effects(texts: Iterable[str]) -> list[EffectSpec]:
    """Several ``--effect`` values; ``none`` means no effect; each effect at most once."""
    specs = [parse_effect(t) for t in texts if t.strip() != "none"]
    check_unique(specs)
    return specs


def check_unique(specs: Iterable[EffectSpec]) -> None:
    """EffectError if an effect is named twice."""
    seen: set[str] = set()
    for spec in specs:
        if spec.name in seen:
            raise EffectError(f"effect {spec.name} given twice")
        seen.add(spec.name)


def register(info: EffectInfo) -> EffectInfo:
    """Add an effect defined outside the kernel (a tenth one): its own module, one call.

    The effect brings a compiled ``weight_force``, or terms of its own (``terms``: its
    hooks, with its continuous ``states`` and its discrete ``slots``), or both; or, a
    gauge effect, what its gauge records (``record``, and ``invert`` for restarts: see
    ``EffectInfo`` and docs/architecture.md); ``sim.physics.added.check`` refuses what the
    model cannot compose. Its flag and parameters get the next free columns of the kernel
    row's extension block, its slots the next of the constants' (the columns and slot
    ``info`` gives are ignored), and a model with it switched on runs a kernel composed
    with it (``sim.physics.compose``). Returns the registered info, as ``EFFECTS`` now
    holds it; ``unregister`` removes it again.
    """
    if info.name in EFFECTS:
        raise EffectError(f"an effect named {info.name!r} is already registered")
    others = tuple(e for e in EFFECTS.values() if e.added)
    added.check(info, others)
    used = [c for e in others for c in _columns(e)]
    first = max(used, default=layout.R_X - 1) + 1
    if first + len(info.params) >= layout.R_X + layout.N_X:
        raise EffectError(
            f"{info.name}: no room in the kernel row ({layout.N_X} columns for added effects)"
        )
    slot = added.slot_range(others)
    if slot + len(info.slots) > layout.S_X + layout.N_SX:
        raise EffectError(
            f"{info.name}: no room for its slots ({layout.N_SX} for added effects' slots)"
        )
    (registered,), _ = layout.place((info,), first)
    registered = replace(registered, slot_index=slot)
    EFFECTS[info.name] = registered
    return registered


def unregister(name: str) -> None:
    """Remove an effect ``register`` added (the nine of STAND.md §5 stay)."""
    info = effect_info(name)
    if not info.added:
        raise EffectError(f"{name} is one of the kernel's own effects; it cannot be removed")
    del EFFECTS[name]


def _columns(info: EffectInfo) -> list[int]:
    return [info.flag_column, *(p.column for p in info.params)]
