"""The fits' search: how a short refit stops."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sim.checks.check import CaseSpec, make_campaign
from sim.config import default_config
from sim.identify.fitting import Candidate, Objective, effect_grid_start, fit
from sim.identify.refitting import REFIT_FTOL
from sim.identify.shooting import dial_slope
from sim.identify.traces import Trace
from sim.params import StandParams

EFFECT = "fibre_viscoelastic"


@pytest.fixture(scope="module")
def campaign() -> tuple[list[Trace], StandParams]:
    """A light-weight campaign of the check (seed 1) with a withheld Maxwell branch."""
    stand = default_config()
    spec = CaseSpec(EFFECT, 3.096, 0, 1)
    traces, _, _ = make_campaign(stand, EFFECT, 3.096, spec.rng())
    slope = dial_slope(traces)
    traces = [dataclasses.replace(tr, dial_slope=slope) for tr in traces]
    return traces, stand.stand_params("final", 3.096)


def _cost(cand: Candidate, traces: list[Trace], nominal: StandParams, v: dict[str, float]) -> float:
    z = np.array([p.to_internal(v[p.name]) for p in cand.params])
    return float(np.sum(Objective(cand, traces, nominal).residuals(z) ** 2))


def test_a_refit_stops_once_a_step_gains_little_and_keeps_its_cost(
    campaign: tuple[list[Trace], StandParams],
) -> None:
    # The same refit with the diagnosis' stopping rule and without: fewer simulations,
    # and the cost where it stopped within half a percent of the full budget's.
    traces, nominal = campaign
    cand = Candidate.build(EFFECT)
    base = fit(Candidate.build(), traces, nominal)
    start = effect_grid_start(cand, traces, nominal, base.values)
    runs = [
        fit(cand, traces, nominal, baseline=start, single_start=True, max_nfev=15, ftol=ftol)
        for ftol in (1e-8, REFIT_FTOL)
    ]
    assert runs[1].evaluations < runs[0].evaluations
    assert runs[1].train_cost <= 1.005 * runs[0].train_cost
    assert runs[1].train_cost < _cost(cand, traces, nominal, start)
