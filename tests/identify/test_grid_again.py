"""A named effect's start grid again at the fit's own baseline, before its polish.

The fixture is a same-form check campaign (``diagnose-check --truth same --seed 8``, the
heavy weight, a pulley with inertia and bearing friction, the moderate recordings)
whose diagnosis named the pulley right but fitted it in another basin: inertia ×0.8 and
bearing torque ×2.4 of the truth, training cost 7.5·10⁻⁴ against the truth's 5.9·10⁻⁴,
no 95 % interval holding a truth. A local polish from there stays there.
"""

from __future__ import annotations

import numpy as np
import pytest

from sim.checks.check import check_cases, make_campaign, recording_set
from sim.config import StandConfig
from sim.identify.candidates import Candidate, FitResult
from sim.identify.fitting import Objective
from sim.identify.refitting import Fitted, polish
from sim.identify.screening import outputs_of

EFFECT = "pulley_inertia_friction"
#: Where that diagnosis's fit ended.
WRONG_BASIN = {
    "stiffness_scale": 0.766468,
    "damping_scale": 1.077646,
    "friction_scale": 0.968404,
    f"{EFFECT}.inertia_kg_m2": 1.17e-4,
    f"{EFFECT}.bearing_torque_n_m": 0.011546,
    f"{EFFECT}.load_coeff": 0.003218,
}


def test_the_polish_leaves_a_wrong_basin_the_grid_again_finds(stand: StandConfig) -> None:
    (spec,) = [s for s in check_cases(8, 1, [EFFECT]) if s.mass_kg > 5.0]
    campaign = recording_set("moderate", stand)
    traces, _, truth = make_campaign(stand, EFFECT, spec.mass_kg, spec.rng(), campaign)
    nominal = stand.stand_params("final", spec.mass_kg)
    candidate = Candidate.build(EFFECT)
    cost = Objective(candidate, traces, nominal)
    start_cost = float(np.sum(cost.residuals(candidate.internal(WRONG_BASIN)) ** 2))
    outs = outputs_of(candidate, WRONG_BASIN, traces, nominal)
    stuck = Fitted(FitResult(candidate, dict(WRONG_BASIN), start_cost, 0), outs, np.inf)
    polished = polish(stuck, traces, nominal).result
    assert polished.train_cost < 0.85 * start_cost
    for name in ("inertia_kg_m2", "bearing_torque_n_m", "load_coeff"):
        assert polished.values[f"{EFFECT}.{name}"] == pytest.approx(truth[name], rel=0.15), name
