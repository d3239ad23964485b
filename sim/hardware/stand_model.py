"""The physics behind the simulated gauges: the baseline model, with effects when asked.

Effects (``sim/effects``, STAND.md §5) plug in by name through ``register_effect``: a
factory receives the model built so far and the effect's text (``NAME[:param=value,...]``)
and returns one that satisfies ``StandModel`` (it may wrap it — a gauge's dynamics, a
time skew — or replace it by a richer one). ``build_stand_model(params, rate_hz,
["name:param=value", ...])`` applies them in order. Without effects the simulated stand
runs ``sim.model.ModelStream``, the baseline.
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable, Sequence

from sim.hardware.gauges import StandModel
from sim.model import ModelStream
from sim.params import StandParams

log = logging.getLogger(__name__)

__all__ = ["EffectFactory", "available_effects", "build_stand_model", "register_effect"]

#: (model so far, stand parameters, sample rate Hz, the effect's text) → model with it.
EffectFactory = Callable[[StandModel, StandParams, float, str], StandModel]
_EFFECTS: dict[str, EffectFactory] = {}


def register_effect(name: str, factory: EffectFactory) -> None:
    """Make an effect available to the simulated stand under ``name``."""
    _EFFECTS[name] = factory


def available_effects() -> list[str]:
    """Effect names the simulated stand can switch on (loads ``sim.effects`` if present)."""
    try:
        importlib.import_module("sim.effects")
    except ModuleNotFoundError as err:
        if err.name not in {"sim.effects"}:
            raise
    return sorted(_EFFECTS)


def build_stand_model(
    params: StandParams, rate_hz: float, effects: Sequence[str] = ()
) -> StandModel:
    """The baseline model at static rest, with the effects applied in order.

    Each effect is ``NAME`` (default parameters) or ``NAME:param=value,...``.

    Raises
    ------
    ValueError
        An effect name nobody registered (the factory raises for bad parameters).
    """
    model: StandModel = ModelStream(params, rate_hz)
    wanted = [e.strip() for e in effects if e.strip() != "none"]
    if wanted:
        known = available_effects()
        for text in wanted:
            name = text.partition(":")[0].strip()
            if name not in _EFFECTS:
                have = ", ".join(known) or "none yet (sim/effects provides them)"
                raise ValueError(f"unknown effect {name!r}; available: {have}")
            model = _EFFECTS[name](model, params, rate_hz, text)
            log.info("simulated stand: effect %s switched on", text)
    return model
