"""The nine effects of STAND.md §5, in its order: the order of the registry and of the row.

One declarative table (python-can's ``MESSAGE_READERS`` shape): nothing registers
itself. ``sim.effects.registry.EFFECTS`` lists them with their row columns, which
``sim.physics.layout`` computes from this order. Reading it loads no numba.
"""

from __future__ import annotations

from sim.effects import (
    channel_time_skew,
    dial_gauge_calibration,
    fibre_pulley_jump,
    fibre_transverse_vibration,
    fibre_viscoelastic,
    force_gauge_dynamics,
    pulley_inertia_friction,
    side_load_friction,
    stick_slip_friction,
)
from sim.effects.info import EffectInfo

__all__ = ["BUILT_IN"]

#: The effects' declarations (columns not yet given: ``sim.physics.layout.PLACED`` has them).
BUILT_IN: tuple[EffectInfo, ...] = tuple(
    module.INFO
    for module in (
        fibre_viscoelastic,
        fibre_transverse_vibration,
        fibre_pulley_jump,
        pulley_inertia_friction,
        stick_slip_friction,
        side_load_friction,
        dial_gauge_calibration,
        channel_time_skew,
        force_gauge_dynamics,
    )
)
