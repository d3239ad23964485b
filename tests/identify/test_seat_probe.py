"""Start points for the pulley-jump refit, read off a recording's seat steps."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from drivers.signals import plan_motion
from sim.config import StandConfig, default_config
from sim.effects import EffectSpec
from sim.effects.fibre_pulley_jump.seat_probe import EFFECT, seat_probes, taut_law
from sim.identify.traces import Trace, make_trace
from sim.model import Model
from sim.situations import SITUATIONS

BASE = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
#: Force gauge noise, N rms (the validation set's order).
NOISE_N = 0.05


@pytest.fixture(scope="module")
def stand() -> StandConfig:
    return default_config()


def _recording(stand: StandConfig, params: dict[str, float] | None) -> Trace:
    """Situation 11 (the fibre goes slack every cycle), with the pulley jump or without."""
    situation = SITUATIONS["11"]
    t, x = plan_motion(situation.signal, stand.drive).sample(stand.sample_rate_hz)
    effects = [EffectSpec(EFFECT, params)] if params is not None else []
    nominal = stand.stand_params("final", situation.mass_kg)
    run = Model(nominal, effects).run(x, stand.sample_rate_hz)
    force = run.force_n + np.random.default_rng(0).normal(0.0, NOISE_N, x.size)
    return make_trace("11", t, x, run.u_m, force, situation.mass_kg)


def _patterns(probes: list[dict[str, float]]) -> set[tuple[float, int]]:
    return {(round(p[f"{EFFECT}.step_m"], 5), int(p[f"{EFFECT}.seats"])) for p in probes}


@pytest.mark.parametrize("seats", [0, 2])
def test_the_recorded_seat_steps_give_the_step_its_sign_and_the_flank_its_seats(
    stand: StandConfig, seats: int
) -> None:
    # A snap re-seat 0.6 mm *down* (the fibre's path longer): the start grid's only
    # negative step level is −0.29 mm; the recording shows the step itself.
    step = -6e-4
    trace = _recording(stand, {"step_m": step, "depth_scale_m": 1e-6, "seats": float(seats)})
    nominal = stand.stand_params("final", trace.mass_kg)
    probes = seat_probes([trace], nominal, BASE)
    patterns = _patterns(probes)
    assert probes, "the steps were not seen"
    steps = {s for s, _ in patterns}
    assert any(abs(s - step) < 0.1 * abs(step) for s in steps)  # the first step from rest
    if seats == 0:
        assert (round(min(steps, key=lambda s: abs(s - step)), 5), 0) in patterns
    else:  # the climb to the flange: two steps, or one step of the whole climb
        assert any(n == seats and abs(s - step) < 0.1 * abs(step) for s, n in patterns)
        assert any(n == 1 and abs(s - seats * step) < 0.1 * abs(step) for s, n in patterns)
    for p in probes:  # the fibre left its groove at no depth: the onset is shallow
        assert 0.0 <= p[f"{EFFECT}.onset_m"] < 1e-3


def test_a_fibre_that_never_re_seats_proposes_no_start(stand: StandConfig) -> None:
    # Slack every cycle, but the seat never moves: the force sits on the fibre's law
    # within the noise after every episode, so no step is read into it.
    trace = _recording(stand, None)
    nominal = stand.stand_params("final", trace.mass_kg)
    assert seat_probes([trace], nominal, BASE) == []


def test_seat_steps_are_read_again_with_the_refits_own_baseline(stand: StandConfig) -> None:
    # The other stand, light weight, brisk recordings: a ratchet of two 0.64 mm seats
    # down. The baseline fit took part of it into k (×0.61) and c (×2.1); every start
    # read and tried there cost more than a two-groove toggle, and the refit ended in
    # that basin. Read again there, the steps give the ratchet: a far better fit.
    from sim.checks.check import CaseSpec, make_campaign
    from sim.checks.otherstand.campaign import OTHER_SETS
    from sim.identify.fitting import Candidate, effect_grid_start, fit
    from sim.identify.refitting import read_again, short_fit
    from sim.identify.shooting import dial_slope

    spec = CaseSpec(EFFECT, 3.096, 0, 1)
    traces, _, truth = make_campaign(
        stand, EFFECT, spec.mass_kg, spec.rng(), (),
        truth_stand="other", other_campaign=OTHER_SETS["brisk"],
    )  # fmt: skip
    slope = dial_slope(traces)
    traces = [dataclasses.replace(tr, dial_slope=slope) for tr in traces]
    nominal = stand.stand_params("final", spec.mass_kg)
    base = fit(Candidate.build(), traces, nominal)
    candidate = Candidate.build(EFFECT)
    probes = seat_probes(traces, nominal, base.values)
    read_at_fit = [p for p in probes if "stiffness_scale" not in p]  # not the taut law's
    start = effect_grid_start(candidate, traces, nominal, base.values, read_at_fit)
    first = short_fit(candidate, traces, nominal, start)
    again = read_again(candidate, traces, nominal, first)
    assert again.train_cost < 0.5 * first.train_cost
    step = truth[f"{EFFECT}.step_m"]
    assert first.values[f"{EFFECT}.seats"] == 0  # the two-groove toggle's basin
    # Read again, the ratchet's whole travel: the other stand counts the seats, this
    # candidate the steps up the flank (with the starts refined over their warm-ups it
    # took one step of 1.28 mm where the truth has two of 0.64: the same travel).
    steps = max(again.values[f"{EFFECT}.seats"], 1.0)
    travel = (truth[f"{EFFECT}.seats"] - 1) * step
    assert abs(steps * again.values[f"{EFFECT}.step_m"] - travel) < 0.1 * abs(travel)
    # The starts read with the taut intervals' own k and c (``taut_law``) reach the
    # ratchet from the first fit.
    both = effect_grid_start(candidate, traces, nominal, base.values, probes)
    direct = short_fit(candidate, traces, nominal, both)
    assert direct.train_cost < 0.5 * first.train_cost
    assert abs(direct.values[f"{EFFECT}.step_m"] - step) < 0.1 * abs(step)


def test_the_taut_intervals_give_the_fibres_law_whatever_the_seat_did(
    stand: StandConfig,
) -> None:
    # A stand 20 % stiffer and 30 % less damped than nominal, its fibre climbing a
    # groove's flank in 0.5 mm steps once a slack loop is 0.5 mm deep. Between slack
    # episodes the seat holds still, so the taut intervals give k and c (an intercept
    # each), however the seat moved.
    situation = SITUATIONS["11"]
    t, x = plan_motion(situation.signal, stand.drive).sample(stand.sample_rate_hz)
    nominal = stand.stand_params("final", situation.mass_kg)
    real = dataclasses.replace(
        nominal,
        stiffness_n_m=1.2 * nominal.stiffness_n_m,
        damping_n_s_m=0.7 * nominal.damping_n_s_m,
    )
    step = 5e-4
    jump = EffectSpec(
        EFFECT, {"step_m": step, "depth_scale_m": 1e-6, "seats": 3.0, "onset_m": 5e-4}
    )
    run = Model(real, [jump]).run(x, stand.sample_rate_hz)
    force = run.force_n + np.random.default_rng(1).normal(0.0, NOISE_N, x.size)
    trace = make_trace("11", t, x, run.u_m, force, situation.mass_kg)
    law = taut_law([trace], nominal)
    assert law is not None
    assert law[0] == pytest.approx(1.2, rel=0.02)
    assert law[1] == pytest.approx(0.7, rel=0.05)
    # Read with a baseline that took the steps into k and c (as a fit without a seat
    # does), the offsets show no clean step; the starts read with the taut law carry it
    # and its k and c.
    wrong = {"stiffness_scale": 0.6, "damping_scale": 4.0, "friction_scale": 1.0}
    probes = seat_probes([trace], nominal, wrong)
    lawful = [p for p in probes if "stiffness_scale" in p]
    assert lawful
    assert all(p["stiffness_scale"] == pytest.approx(law[0]) for p in lawful)
    assert any(abs(p[f"{EFFECT}.step_m"] - step) < 0.1 * step for p in lawful)
