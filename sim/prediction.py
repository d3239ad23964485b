"""The safety prediction: a motion simulated over a plausible range of the stand's model.

``predict`` runs the model (the nominal stand, or one a diagnosis fitted, with its
effects) at the centre and the 8 corners of a ``Spread`` of stiffness, damping and
friction in one batch (≈ 20 ms for a 4 s motion) and keeps each figure's worst
(``sim.envelope``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from sim.effects.registry import EffectSpec
from sim.envelope import Prediction, Spread, figures_of, worst_of
from sim.model import Model, Variant
from sim.params import StandParams

__all__ = ["centre_stand", "corner_variants", "predict"]


def corner_variants(stand: StandParams, spread: Spread) -> list[Variant]:
    """The spread's centre and corners as the model's variants of ``stand``."""
    return [
        {
            "stiffness_n_m": stand.stiffness_n_m * k,
            "damping_n_s_m": stand.damping_n_s_m * c,
            "friction_scale": stand.friction_scale * f,
        }
        for k, c, f in spread.corners()
    ]


def centre_stand(stand: StandParams, spread: Spread) -> StandParams:
    """``stand`` at the spread's centre: the fitted stand the planner's rivals stand on."""
    return stand.with_(**corner_variants(stand, spread)[0])


def predict(
    stand: StandParams,
    effects: Sequence[EffectSpec],
    x_m: NDArray[np.float64],
    rate_hz: float,
    spread: Spread,
    slack_force_n: float,
) -> Prediction:
    """The motion's figures at the spread's centre and worst over its corners.

    Parameters
    ----------
    stand
        The nominal stand at the run's mass; the spread's factors multiply its fibre
        stiffness, damping and friction scale.
    effects
        Effects the model has (a diagnosis' named ones, at their fitted values).
    x_m
        Drive position at ``rate_hz``, m (downward positive), from rest.
    rate_hz
        Sample rate, Hz.
    spread
        The plausible range of the three factors.
    slack_force_n
        The slack rule's threshold, N.
    """
    variants = corner_variants(stand, spread)
    res = Model(stand, effects).run_batch(x_m, rate_hz, variants)
    figures = [
        figures_of(res.true_force_n[i], res.force_n[i], res.true_u_m[i], rate_hz, slack_force_n)
        for i in range(len(variants))
    ]
    return Prediction(figures[0], worst_of(figures), len(figures))
