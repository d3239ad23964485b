"""The fits' search: how a short refit stops."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sim.checks.check import CaseSpec, make_campaign
from sim.config import default_config
from sim.identify.fitting import Candidate, Objective, effect_grid_start, fit, weighed_by_miss
from sim.identify.refitting import REFIT_FTOL
from sim.identify.screening import outputs_of
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


def test_a_fit_in_a_reference_miss_counts_each_recorded_channel_alike(
    campaign: tuple[list[Trace], StandParams],
) -> None:
    # In the units of the baseline's own miss (``weighed_by_miss``), every trace's u and
    # F cost about 1 each at the baseline's values, as the held-out test's geometric mean
    # weighs them; in each channel's spread, the force outweighs the precise dial gauge.
    traces, nominal = campaign
    base = fit(Candidate.build(), traces, nominal)
    reference = outputs_of(base.candidate, base.values, traces, nominal)
    weighed = weighed_by_miss(traces, reference)
    assert all(w.segments is tr.segments for w, tr in zip(weighed, traces, strict=True))
    z = np.array([p.to_internal(base.values[p.name]) for p in base.candidate.params])
    for tr in weighed:
        assert tr.fit_units is not None and all(u > 0 for u in tr.fit_units)
        residuals = Objective(base.candidate, [tr], nominal).residuals(z)
        half = residuals.size // 2  # u's residuals, then F's
        shares = [float(np.sum(residuals[:half] ** 2)), float(np.sum(residuals[half:] ** 2))]
        assert shares == pytest.approx([1.0, 1.0], rel=0.2)
        spread = Objective(base.candidate, [dataclasses.replace(tr, fit_units=None)], nominal)
        r = spread.residuals(z)
        assert np.sum(r[:half] ** 2) < 0.1 * np.sum(r[half:] ** 2)
    # A channel the reference matched exactly has no miss to count in: its spread is.
    exact = dataclasses.replace(weighed[0], fit_units=(0.0, 1.0))
    plain = dataclasses.replace(weighed[0], fit_units=None)
    u_exact = Objective(base.candidate, [exact], nominal).residuals(z)
    u_plain = Objective(base.candidate, [plain], nominal).residuals(z)
    half = u_plain.size // 2
    np.testing.assert_array_equal(u_exact[:half], u_plain[:half])
