"""A gross misfit: a held-out error beyond what the fitted model leaves on its own recordings."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sim.checks.check import SMALL_CAMPAIGN, make_campaign
from sim.config import StandConfig
from sim.identify.adequacy import GROSS_ALPHA, OwnExcess, own_excess, prediction_bound
from sim.identify.fitting import Candidate
from sim.identify.heldout import heldout_excess
from sim.identify.remainder import remainder_of, verdict
from sim.identify.replicates import reading_step
from sim.identify.screening import outputs_of
from sim.identify.traces import Trace
from sim.params import StandParams

HEAVY = 8.131
Campaign = tuple[list[Trace], dict[str, float], StandParams]


def test_one_more_draw_exceeds_the_prediction_bound_about_as_often_as_its_alpha() -> None:
    # Log-normal excesses (what replicates of a right model give): the bound from eight
    # of them is passed by a ninth at GROSS_ALPHA; a known noise unit only narrows it.
    rng = np.random.default_rng(0)
    trials = 20000
    draws = np.exp(rng.normal(0.3, 0.1, (trials, 9)))
    passed = sum(row[8] > prediction_bound(row[:8], 0.0) for row in draws)
    assert 0.3 * GROSS_ALPHA * trials <= passed <= 2.5 * GROSS_ALPHA * trials
    wider = sum(row[8] > prediction_bound(row[:8], 0.05) for row in draws[:2000])
    assert wider <= sum(row[8] > prediction_bound(row[:8], 0.0) for row in draws[:2000])
    assert prediction_bound([1.2, 1.3, 1.25], 0.0) > 1.3


@pytest.fixture(scope="module")
def campaign(stand: StandConfig) -> Campaign:
    """A clean heavy campaign, its true baseline scales and the nominal stand."""
    traces, _, truth = make_campaign(stand, "none", HEAVY, np.random.default_rng(4), SMALL_CAMPAIGN)
    scales = {k: truth[k] for k in ("stiffness_scale", "damping_scale", "friction_scale")}
    return traces, scales, stand.stand_params("final", HEAVY)


def test_the_true_model_lies_within_its_own_replicates_and_a_wrong_one_does_not(
    campaign: Campaign,
) -> None:
    traces, truth, nominal = campaign
    base = Candidate.build()
    right = heldout_excess(traces, outputs_of(base, truth, traces, nominal))
    own, sims = own_excess(base, truth, traces, nominal, right)
    assert not own.gross
    assert sims == len(traces) * (1 + len(own.replicates))
    # The replicates leave what the recordings leave: the same noise, the same restarts.
    assert own.bound > right > 0.8 * min(own.replicates)
    wrong_values = {**truth, "stiffness_scale": 0.7 * truth["stiffness_scale"]}
    wrong = heldout_excess(traces, outputs_of(base, wrong_values, traces, nominal))
    own_wrong, _ = own_excess(base, wrong_values, traces, nominal, wrong)
    assert own_wrong.gross
    assert own_wrong.to_dict()["gross"] is True


def test_a_gross_misfit_that_no_signature_repeats_is_not_called_adequate(
    campaign: Campaign,
) -> None:
    # A misfit irregular from cycle to cycle: every held-out cycle's force off by a
    # different random offset, the training cycles' off by ± the same amount in turn
    # (no mean to repeat: random ones there shared one by chance, and with the restarts
    # refined over their warm-ups the "repeats with the motion" term found it), so no
    # signature of the training cycles predicts the held-out ones.
    traces, truth, nominal = campaign
    rng = np.random.default_rng(7)
    base = Candidate.build()
    outputs = outputs_of(base, truth, traces, nominal)
    for tr, out in zip(traces, outputs, strict=True):
        sign = 1.0
        for c in np.unique(tr.cycle):
            at = tr.cycle == c
            if tr.train[at].all():
                out.force_n[at] += sign * 40.0 * tr.noise_force_n
                sign = -sign
            else:
                out.force_n[at] += rng.normal(0.0, 40.0 * tr.noise_force_n)
    excess = heldout_excess(traces, outputs)
    remainder, _ = remainder_of(traces, outputs, nominal, truth, excess, candidate=base)
    assert remainder.own is not None and remainder.own.gross and remainder.beyond_noise
    assert verdict(False, remainder) == "unexplained"
    assert "too few, or the misfit too irregular" in remainder.state
    # Where effects are named the comparison is reported, and the signatures decide.
    beside, _ = remainder_of(traces, outputs, nominal, truth, excess, candidate=base, named=True)
    assert beside.own is not None and beside.own.gross
    assert beside.beyond_noise == any(s.passes for s in beside.signature)
    alone, _ = remainder_of(traces, outputs, nominal, truth, excess)
    if not any(s.passes for s in alone.signature):
        assert verdict(False, alone) == "baseline_adequate"  # what the guard is for


def test_a_channel_read_in_counts_is_replicated_in_counts() -> None:
    # A dial gauge read in 1 µm counts whose noise is a third of a count: at rest it reads
    # one count throughout (no rest noise), in motion it is off by up to half a count.
    rng = np.random.default_rng(2)
    motion = 50e-6 * np.sin(np.linspace(0.0, 20.0, 8000))
    read = np.round((motion + rng.normal(0.0, 0.3e-6, motion.size)) / 1e-6) * 1e-6
    assert reading_step(read) == pytest.approx(1e-6, rel=1e-6)
    assert reading_step(motion) == 0.0  # floating point: steps of every size
    assert reading_step(read + rng.normal(0.0, 1e-9, read.size)) == 0.0
    assert reading_step(np.full(100, 3e-6)) == 0.0  # never moves: no count to read


def test_replicates_without_noise_in_a_channel_give_no_bound() -> None:
    # A channel with no noise at all in the replicates (a gauge read in steps too fine to
    # see, at rest reading one value) gives them no error there, and their pooled excess
    # collapses (1e-75): no bound is drawn from that, nothing is called gross, and the JSON
    # stays JSON.
    assert prediction_bound([1e-75] * 8, 0.05) == float("inf")
    own = OwnExcess(50.0, (1e-75,) * 8, prediction_bound([1e-75] * 8, 0.05))
    assert not own.gross
    assert json.loads(json.dumps(own.to_dict()))["bound"] is None
