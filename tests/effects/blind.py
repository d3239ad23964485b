"""A campaign drawn with an added effect, diagnosed blind against every registered one."""

from __future__ import annotations

import importlib

import numpy as np

from sim.checks.check import SMALL_CAMPAIGN, make_campaign
from sim.config import StandConfig
from sim.effects import EFFECTS
from sim.identify import Diagnosis


def named_blind(
    stand: StandConfig, name: str, mass: float, seed: int
) -> tuple[Diagnosis, dict[str, float]]:
    """The diagnosis (it must name ``name``, ranking every effect) and the true parameters.

    The campaign is drawn as the check draws one: a "real" stand, the effect's
    parameters, the gauges' noise.
    """
    traces, _, truth = make_campaign(
        stand, name, mass, np.random.default_rng(seed), SMALL_CAMPAIGN, open_loop_oracle=True
    )
    diagnose = importlib.import_module("sim.identify.pipeline").diagnose
    result: Diagnosis = diagnose(traces, stand.stand_params("final", mass))
    assert len(result.ranking) == len(EFFECTS)
    assert result.effect == name, [(r.effect, r.p_value) for r in result.ranking]
    return result, truth
