"""The physics behind the simulated gauges: the model, with effects when asked.

``build_stand_model(params, rate_hz, ["name:param=value", ...])`` parses the effects
(``sim.effects``, STAND.md §5) and returns the front door's stream
(``sim.model.Model(...).stream``): the baseline without effects, the augmented model
with them. The effects are found in the ``EFFECTS`` registry dict; nothing registers
itself by being imported.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

from sim.effects.registry import EFFECTS, parse_effects
from sim.hardware.gauges import StandModel
from sim.model import Model
from sim.params import StandParams

log = logging.getLogger(__name__)

__all__ = ["available_effects", "build_stand_model"]


def available_effects() -> list[str]:
    """Effect names the simulated stand can switch on."""
    return sorted(EFFECTS)


def build_stand_model(
    params: StandParams, rate_hz: float, effects: Sequence[str] = ()
) -> StandModel:
    """The model at static rest, with the effects switched on.

    Each effect is ``NAME`` (default parameters) or ``NAME:param=value,...``.

    Raises
    ------
    EffectError
        An unknown effect or parameter, a value out of range, an effect named twice
        (a ValueError).
    """
    specs = parse_effects(effects)
    for spec in specs:
        log.info("simulated stand: effect %s switched on", spec)
    return Model(params, specs).stream(rate_hz)
