"""The effects as plug-ins of the simulated stand (``sim.hardware.stand_model``).

Importing ``sim.effects`` registers one factory per effect name. Each factory turns the
model built so far into an ``AugmentedStream`` with its effect added (at the parameters
its text gives, defaults otherwise), so several combine into one augmented model,
applied in the given order.
"""

from __future__ import annotations

from collections.abc import Callable

from sim.effects.registry import EFFECTS, EffectError, check_unique, parse_effect
from sim.effects.simulator import AugmentedStream
from sim.hardware.gauges import StandModel
from sim.hardware.stand_model import register_effect
from sim.model import ModelStream
from sim.params import StandParams

__all__ = ["register_all"]


def _factory(name: str) -> Callable[[StandModel, StandParams, float, str], StandModel]:
    def build(model: StandModel, params: StandParams, rate_hz: float, text: str) -> StandModel:
        if isinstance(model, AugmentedStream):
            before = list(model.effects)
        elif isinstance(model, ModelStream):
            before = []
        else:
            raise EffectError(f"{name}: cannot add an effect to a {type(model).__name__}")
        spec = parse_effect(text)
        if spec.name != name:
            raise EffectError(f"{text!r} is not the effect {name}")
        check_unique([*before, spec])
        return AugmentedStream(params, rate_hz, [*before, spec])

    return build


def register_all() -> None:
    """Register every effect of ``EFFECTS`` with the simulated stand."""
    for name in EFFECTS:
        register_effect(name, _factory(name))
