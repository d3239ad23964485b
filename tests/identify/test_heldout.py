"""Held-out scoring: the error in noise units that decides between candidates."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from sim.checks.check import SMALL_CAMPAIGN, make_campaign
from sim.config import StandConfig
from sim.identify.heldout import (
    Outputs,
    bootstrap_confidence,
    cycle_improvements,
    heldout_error,
    heldout_excess,
)
from sim.identify.traces import Trace


@pytest.fixture(scope="module")
def campaign(stand: StandConfig) -> tuple[list[Trace], list[Outputs]]:
    traces, oracle, _ = make_campaign(
        stand, "none", 8.131, np.random.default_rng(4), SMALL_CAMPAIGN, open_loop_oracle=True
    )
    return traces, oracle


def test_the_true_noise_free_outputs_score_one_noise_unit(
    campaign: tuple[list[Trace], list[Outputs]],
) -> None:
    traces, oracle = campaign
    # What is left of a perfect model is the sensor noise, estimated from the rest.
    assert heldout_excess(traces, oracle) == pytest.approx(1.0, abs=0.1)


def test_a_small_dial_gauge_error_stands_out_in_noise_units_not_in_pooled_nrmse(
    campaign: tuple[list[Trace], list[Outputs]],
) -> None:
    traces, oracle = campaign
    gained = [Outputs(o.u_m * 1.002, o.force_n) for o in oracle]
    # A 0.2 % gain error is many times the dial gauge's noise (the u channels' error
    # grows about sevenfold; pooled geometrically with the untouched force channels,
    # X more than doubles)…
    assert heldout_excess(traces, gained) > 2 * heldout_excess(traces, oracle)
    # …but pooled with the noisier force channel it hardly moves the NRMSE.
    assert heldout_error(traces, gained) < 1.15 * heldout_error(traces, oracle)
    gains = cycle_improvements(traces, gained, oracle)
    assert np.all(gains > 0) and bootstrap_confidence(gains) == 1.0
    assert bootstrap_confidence(-gains) == 0.0


def test_a_silent_channel_does_not_weigh_without_bound(
    campaign: tuple[list[Trace], list[Outputs]],
) -> None:
    traces, oracle = campaign
    # A quantised gauge can read exactly zero noise at rest.
    quiet = [replace(tr, noise_u_m=0.0, noise_force_n=0.0) for tr in traces]
    assert np.isfinite(heldout_excess(quiet, oracle))
    assert heldout_excess(quiet, oracle) > heldout_excess(traces, oracle)
