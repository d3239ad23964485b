"""Form parameters: held in every refit, fitted for the leading candidate (LuGre's σ₀)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sim.checks.check import SMALL_CAMPAIGN, CaseSpec, make_campaign
from sim.config import default_config
from sim.identify.fitting import Candidate, fit, grid_axis
from sim.identify.refitting import refine_form, refit
from sim.identify.shooting import dial_slope
from sim.identify.traces import Trace
from sim.params import StandParams

EFFECT = "stick_slip_friction"
SIGMA = f"{EFFECT}.bristle_stiffness_n_m"


def _campaign(truth_stand: str, seed: int) -> tuple[list[Trace], StandParams]:
    """A heavy stick-slip campaign: the candidate's own form (short) or the other stand's."""
    stand = default_config()
    rng = CaseSpec(EFFECT, 8.131, 0, seed).rng()
    if truth_stand == "same":
        traces, _, _ = make_campaign(stand, EFFECT, 8.131, rng, SMALL_CAMPAIGN)
    else:
        traces, _, _ = make_campaign(stand, EFFECT, 8.131, rng, truth_stand="other")
    slope = dial_slope(traces)
    traces = [dataclasses.replace(t, dial_slope=slope) for t in traces]
    return traces, stand.stand_params("final", 8.131)


def test_a_form_parameter_is_held_in_grids_and_fits_until_freed() -> None:
    cand = Candidate.build(EFFECT)
    (sigma,) = [p for p in cand.params if p.name == SIGMA]
    assert sigma.held == pytest.approx(1.0e5)
    assert grid_axis(sigma, 5) == pytest.approx([np.log(1.0e5)])
    # A start that lacks it takes the held value; a freed candidate fits it.
    start = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
    start |= {f"{EFFECT}.static_ratio": 0.4, f"{EFFECT}.stribeck_speed_m_s": 3e-3}
    start |= {f"{EFFECT}.stribeck_exponent": 2.0}
    assert cand.natural(cand.internal(start))[SIGMA] == pytest.approx(1.0e5)
    freed = cand.freed()
    assert all(p.held is None for p in freed.params)
    assert [p.name for p in freed.params] == [p.name for p in cand.params]


def test_a_stand_that_sticks_without_presliding_fits_a_stiff_bristle() -> None:
    # The other stand's stick-slip is a Stribeck curve with a Karnopp stick band: a stuck
    # weight does not move at all, the stiff limit of LuGre's bristle. Held at 1e5 N/m
    # (presliding of 45 µm at the heavy weight's friction) the refit explains part of it;
    # with σ₀ fitted the training cost and the held-out excess fall, σ₀ well above 1e5.
    traces, nominal = _campaign("other", 2)
    base = fit(Candidate.build(), traces, nominal)
    held = refit(Candidate.build(EFFECT), traces, nominal, base.values)
    assert held.result.values[SIGMA] == pytest.approx(1.0e5)
    refined, sims = refine_form(held, traces, nominal, lambda _msg: None)
    assert sims > 0
    assert refined.result.values[SIGMA] > 3.0e5
    assert refined.result.train_cost < 0.5 * held.result.train_cost
    assert refined.excess < 0.7 * held.excess


def test_a_lugre_stand_keeps_its_presliding_stiffness_when_its_form_is_fitted() -> None:
    # The candidate's own form at its default σ₀ (1e5 N/m): freeing σ₀ finds it again.
    traces, nominal = _campaign("same", 1)
    base = fit(Candidate.build(), traces, nominal)
    held = refit(Candidate.build(EFFECT), traces, nominal, base.values)
    refined, sims = refine_form(held, traces, nominal, lambda _msg: None)
    assert sims > 0  # it was fitted, and stayed near the truth
    assert 0.5e5 < refined.result.values[SIGMA] < 2.0e5
    assert refined.result.train_cost <= held.result.train_cost


def test_a_candidate_without_form_parameters_is_not_refitted() -> None:
    traces, nominal = _campaign("same", 1)
    base = fit(Candidate.build(), traces, nominal)
    fitted = refit(Candidate.build("side_load_friction"), traces, nominal, base.values)
    again, sims = refine_form(fitted, traces, nominal, lambda _msg: None)
    assert sims == 0 and again is fitted
