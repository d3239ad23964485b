"""What remains after the named effects: the verdict and the remainder's signature."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.signal import lfilter

from labstand.diagnosis_report import write_report
from sim.checks.check import FULL_CAMPAIGN, CaseSpec, make_campaign, recording_set
from sim.checks.otherstand.campaign import make_other_campaign
from sim.checks.otherstand.gauges import Realism
from sim.checks.otherstand.outside import force_drift
from sim.config import StandConfig
from sim.effects import EFFECTS, EffectSpec
from sim.identify import diagnose, make_trace, naming
from sim.identify.fitting import Candidate, fit
from sim.identify.heldout import heldout_excess
from sim.identify.refitting import Fitted
from sim.identify.remainder import judge_signatures, verdict
from sim.identify.screening import outputs_of
from sim.identify.signature import (
    _branch_response,
    _mode_response,
    _taut_filters,
    fit_baseline_terms,
    fit_signatures,
    fit_together,
    stlsq,
)
from sim.identify.traces import Trace
from sim.model import Model

LIGHT, HEAVY = 3.096, 8.131
#: Candidates for the short diagnoses here: two gauges that a drifting or curved reading
#: could be blamed on, and a physical effect.
CANDIDATES = ["dial_gauge_calibration", "channel_time_skew", "fibre_viscoelastic"]


def _outside(stand: StandConfig, truth: str, mass: float, seed: int) -> list[Trace]:
    """The other stand's small campaign with one truth (an effect, ``none``, ``artefacts``)."""
    traces, _, _ = make_campaign(
        stand, truth, mass, np.random.default_rng(seed), truth_stand="outside",
        other_campaign=recording_set("moderate", stand)[2:],
    )  # fmt: skip
    return traces


def test_stlsq_recovers_a_sparse_law_and_drops_the_rest() -> None:
    rng = np.random.default_rng(0)
    design = rng.standard_normal((4000, 6))
    truth = np.array([0.0, 2.0, 0.0, 0.0, -0.7, 0.0])
    target = design @ truth + 0.05 * rng.standard_normal(4000)
    coef = stlsq(design, target, threshold=0.2)
    assert np.flatnonzero(coef).tolist() == [1, 4]
    assert coef[[1, 4]] == pytest.approx([2.0, -0.7], abs=0.01)


def test_taut_responses_have_the_static_limits_of_the_force_balance(stand: StandConfig) -> None:
    # A steady force f on the weight is carried by the fibre: the tension changes by
    # -f/n and the weight moves by f/(n²k). A steady extra tension g in the fibre's law
    # changes no force (the weight's balance fixes it) but the elongation, by g/(n·k).
    nominal = stand.stand_params("final", HEAVY)
    values = {"stiffness_scale": 1.1, "damping_scale": 0.9}
    n, k = nominal.projection, nominal.stiffness_n_m * 1.1
    filters = _taut_filters(HEAVY, nominal, values, 2000.0)
    step = np.ones(20000)  # 10 s: the lightly damped taut mode has settled
    (wu, wf), (tu, tf) = filters["weight"], filters["tension"]
    assert lfilter(*wu, step)[-1] == pytest.approx(1 / (n * n * k), rel=1e-4)
    assert lfilter(*wf, step)[-1] == pytest.approx(-1 / n, rel=1e-4)
    assert lfilter(*tu, step)[-1] == pytest.approx(1 / (n * k), rel=1e-4)
    assert abs(lfilter(*tf, step)[-1]) < 1e-4


def test_a_reading_off_in_two_ways_is_fitted_by_both_variants_together(
    stand: StandConfig,
) -> None:
    # The model's own heavy recordings, their force read by a gauge that rings (a 60 Hz
    # mode, half of the tension's dynamic part) and drifts (0.8 N, P2 over each
    # recording): each variant alone leaves the other's share; together they leave the
    # noise, with both sizes found.
    nominal = stand.stand_params("final", HEAVY)
    base = Candidate.build()
    values = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
    drives, _, _ = make_campaign(stand, "none", HEAVY, np.random.default_rng(5), FULL_CAMPAIGN[:2])
    rng = np.random.default_rng(4)
    read = []
    for tr in drives:
        run = Model(nominal, []).run(tr.x_m, tr.rate_hz)
        u = run.u_m - run.u_m[0] + rng.normal(0.0, 2e-6, tr.samples)
        z = np.linspace(-1.0, 1.0, tr.samples)
        ringing = 0.5 * _mode_response(run.force_n, 60.0, tr.rate_hz)
        f = run.force_n + ringing + 0.8 * (1.5 * z * z - 0.5) + rng.normal(0.0, 0.05, tr.samples)
        t = np.arange(tr.samples) / tr.rate_hz
        read.append(make_trace(tr.name, t, tr.x_m, u, f, HEAVY))
    outputs = outputs_of(base, values, read, nominal)
    alone = {f.name: f for f in fit_signatures(read, outputs, nominal, values)}
    variants = [("resonance", "F"), ("drift", "F")]
    together = fit_together(read, outputs, nominal, values, variants)
    assert (together.name, together.channel) == ("resonance in F, drift in F", "F")
    x_together = heldout_excess(read, together.outputs)
    x_alone = [heldout_excess(read, alone[f"{k} in {c}"].outputs) for k, c in variants]
    assert x_together < 0.7 * min(x_alone), (x_together, x_alone)
    assert x_together < 1.2
    ringing_n = re.findall(r"([-+][\d.]+) N·mode 60 Hz", together.formula)
    drift_n = re.findall(r"([-+][\d.]+) N·\w+: P2\(t\)", together.formula)
    assert [float(v) for v in ringing_n] == [pytest.approx(0.5, abs=0.03)]
    assert [float(v) for v in drift_n] == [pytest.approx(0.8, abs=0.05)] * len(read)
    # One variant fitted "together" is that variant's own fit.
    single = fit_together(read, outputs, nominal, values, variants[:1])
    assert heldout_excess(read, single.outputs) == pytest.approx(x_alone[0], rel=1e-9)


def test_a_branch_stretch_relaxes_with_its_time_and_holds_rate_times_tau() -> None:
    # A Maxwell branch's stretch s/(s + 1/τ) of the elongation: a held elongation
    # relaxes to e^(−t/τ) of its step; a steady elongation rate r holds r·τ.
    rate, tau = 2000.0, 0.02
    t = np.arange(4000) / rate
    step = _branch_response(np.ones(t.size), tau, rate)
    assert step[0] == pytest.approx(1.0, rel=0.03)
    assert step[int(tau * rate)] == pytest.approx(np.exp(-1.0), rel=0.02)
    ramp = _branch_response(0.01 * t, tau, rate)
    assert ramp[-1] == pytest.approx(0.01 * tau, rel=1e-3)


def _heavy_recordings(stand: StandConfig, true: list[EffectSpec]) -> list[Trace]:
    """The stand's heavy medium and slow recordings of a model with ``true`` effects.

    At the nominal (``final``) stand, read with 2 µm and 0.05 N of noise.
    """
    nominal = stand.stand_params("final", HEAVY)
    drives, _, _ = make_campaign(stand, "none", HEAVY, np.random.default_rng(5), FULL_CAMPAIGN[1:3])
    rng = np.random.default_rng(7)
    read = []
    for tr in drives:
        run = Model(nominal, true).run(tr.x_m, tr.rate_hz)
        u = run.u_m - run.u_m[0] + rng.normal(0.0, 2e-6, tr.samples)
        f = run.force_n + rng.normal(0.0, 0.05, tr.samples)
        t = np.arange(tr.samples) / tr.rate_hz
        read.append(make_trace(tr.name, t, tr.x_m, u, f, HEAVY))
    return read


def test_one_more_relaxation_branch_describes_a_missing_branch_best_of_the_forms(
    stand: StandConfig,
) -> None:
    # A named viscoelastic's richer forms: the stand's heavy recordings (medium and
    # slow) with a Maxwell branch of 0.2·k relaxing in 20 ms, against the model without
    # it at the true baseline. Linearised through the taut dynamics (which a weight that
    # sticks leaves), the bank of branches takes more than half the held-out error away,
    # clearly more than a curved or a ringing tension (the forms a branch had before):
    # X 75 → 30 against 40.
    nominal = stand.stand_params("final", HEAVY)
    k = nominal.stiffness_n_m
    branch = EffectSpec("fibre_viscoelastic",
                        {"branch_stiffness_n_m": 0.2 * k, "relaxation_time_s": 0.02})  # fmt: skip
    values = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
    read = _heavy_recordings(stand, [branch])
    outputs = outputs_of(Candidate.build(), values, read, nominal)
    x_before = heldout_excess(read, outputs)
    x_after = {}
    for kind in ("relaxation", "strain", "resonance"):
        form = fit_together(read, outputs, nominal, values, [(kind, "u+F")])
        x_after[kind] = heldout_excess(read, form.outputs)
    assert x_after["relaxation"] < 0.5 * x_before, (x_before, x_after)
    assert x_after["relaxation"] < 0.85 * min(x_after["strain"], x_after["resonance"]), x_after


def test_a_side_load_s_richer_form_is_a_friction_growing_with_the_tension(
    stand: StandConfig,
) -> None:
    # A side load named at half its true wall friction (the heavy recordings, the true
    # baseline): what remains is a friction against the weight's motion that grows with
    # the tension. The side load's richer form describes it beyond what the baseline's
    # own terms refitted do, and better than the fibre's law beyond linear (its richer
    # form before, which is no friction; behind the other stand's light side load it set
    # the string modes, a branch and a pulley's inertia aside): X 81 → 39 against 48, 60.
    nominal = stand.stand_params("final", HEAVY)
    values = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
    read = _heavy_recordings(stand, [EffectSpec("side_load_friction", {"friction_coeff": 0.2})])
    named = dict(values, **{"side_load_friction.friction_coeff": 0.1})
    outputs = outputs_of(Candidate.build("side_load_friction"), named, read, nominal)
    x_before = heldout_excess(read, outputs)
    own = heldout_excess(read, fit_baseline_terms(read, outputs, nominal, named).outputs)
    x_after = {
        kind: heldout_excess(
            read, fit_together(read, outputs, nominal, named, [(kind, "u+F")]).outputs
        )
        for kind in ("friction", "strain")
    }
    assert ("friction", "u+F") in EFFECTS["side_load_friction"].richer
    assert ("strain", "u+F") not in EFFECTS["side_load_friction"].richer
    assert x_after["friction"] < 0.7 * own < x_before, (x_before, own, x_after)
    assert x_after["friction"] < 0.85 * x_after["strain"], x_after


@pytest.fixture(scope="module")
def clean_heavy(stand: StandConfig) -> list[Trace]:
    return _outside(stand, "none", HEAVY, 11)


def test_a_drifting_force_zero_is_described_as_drift_in_the_force_channel(
    stand: StandConfig, clean_heavy: list[Trace], tmp_path: Path
) -> None:
    traces = [
        dataclasses.replace(
            tr,
            force_n=force_drift(tr.force_n, tr.rate_hz, {"drift_n": 1.2, "time_constant_s": 4.0}),
        )
        for tr in clean_heavy
    ]
    result = diagnose(traces, stand.stand_params("final", HEAVY), CANDIDATES)
    assert result.verdict == "unexplained"
    assert result.effects == []
    assert result.remainder is not None and result.remainder.beyond_noise
    passing = [s for s in result.remainder.signature if s.passes]
    assert (passing[0].kind, passing[0].channel) == ("drift", "F")
    assert passing[0].source == "balances"
    # In the model's outputs too, where it closes most of the remainder.
    outputs = next(s for s in passing if s.source == "outputs" and s.kind == "drift")
    assert outputs.channel == "F" and outputs.closes > 0.5
    # The report shows it: the balance it was found in against the drift term's fit.
    best = passing[0].series
    assert [part.name for part in best] == [tr.name for tr in traces]
    assert all(part.tension.size == tr.samples for part, tr in zip(best, traces, strict=True))
    drift_in_tension = np.concatenate([p.tension_term[p.taut] for p in best])
    assert np.ptp(drift_in_tension) > 0.5  # the 1.2 N drift, seen in the fibre's law
    index = write_report(tmp_path / "report", traces, result)
    assert (tmp_path / "report" / "remainder.png").stat().st_size > 0
    page = index.read_text(encoding="utf-8")
    assert "unexplained" in page and "the balances" in page
    assert "behaves like a drift term in F (fitted to the balances)" in page  # first screen


@pytest.mark.parametrize("noise_scale", [0.3, 1.0, 3.0])
def test_a_clean_campaign_keeps_baseline_adequate_at_any_noise_level(
    stand: StandConfig, noise_scale: float
) -> None:
    # A right model (the other stand without effects) recorded with a tenth to three
    # times the validation set's noise: the held-out error in noise units moves, but it
    # is no systematic gap.
    nominal = stand.stand_params("final", HEAVY)
    realism = Realism(
        force_rms_n=0.3 * noise_scale, hum_n=0.2 * noise_scale,
        displacement_rms_m=5e-6 * noise_scale,
    )  # fmt: skip
    camp = make_other_campaign(
        nominal, [], np.random.default_rng(21), recording_set("moderate", stand)[2:],
        stand.sample_rate_hz, realism=realism,
    )  # fmt: skip
    traces = [make_trace(name, t, x, u, f, HEAVY) for name, t, x, u, f in camp.recordings]
    result = diagnose(traces, nominal, CANDIDATES)
    assert result.verdict == "baseline_adequate"
    assert result.remainder is not None and not result.remainder.beyond_noise


@pytest.mark.parametrize("scale_error", [0.0, 5e-5])
def test_the_model_s_own_recordings_leave_no_missing_force_in_the_balances(
    stand: StandConfig, scale_error: float
) -> None:
    # The model's own recordings (its outputs plus the gauges' noise), with the dial's
    # scale as estimated from a live recording (5·10⁻⁵ off) or exact. What the low-pass,
    # the derivatives, the one-spring fibre law and the scale leave in the balances is
    # the model's as much as the recording's: no term may pass for a missing force
    # (before the model's own balances were taken off, a position term passed here with
    # the scale off).
    nominal = stand.stand_params("final", HEAVY)
    base = Candidate.build()
    values = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
    slope = (1.0 + scale_error) / nominal.projection
    # ``make demo``'s motions (the paper's situations 11 and 10, the heavy weight) with
    # the simulated stand's quiet gauges (0.02 N, 0.5 µm rms).
    drives, _, _ = make_campaign(stand, "none", HEAVY, np.random.default_rng(5), FULL_CAMPAIGN[:2])
    rng = np.random.default_rng(3)
    for _ in range(2):
        read = []
        for tr in drives:
            run = Model(nominal, []).run(tr.x_m, tr.rate_hz)
            u = run.u_m - run.u_m[0] + rng.normal(0.0, 5e-7, tr.samples)
            f = run.force_n + rng.normal(0.0, 0.02, tr.samples)
            t = np.arange(tr.samples) / tr.rate_hz
            read.append(dataclasses.replace(make_trace(tr.name, t, tr.x_m, u, f, HEAVY),
                                            dial_slope=slope))  # fmt: skip
        outputs = outputs_of(base, values, read, nominal)
        signatures, _, _ = judge_signatures(read, outputs, nominal, values, balances=True)
        balances = [s for s in signatures if s.source == "balances"]
        assert balances, "the balances were not judged"
        assert not [s for s in balances if s.passes], [
            (s.kind, s.channel, s.closes, s.p_family) for s in balances if s.passes
        ]


def test_verdicts_join_what_was_named_with_what_remains(
    stand: StandConfig, clean_heavy: list[Trace]
) -> None:
    nominal = stand.stand_params("final", HEAVY)
    result = diagnose(clean_heavy, nominal, CANDIDATES)
    remainder = result.remainder
    assert remainder is not None
    assert verdict(False, remainder) == "baseline_adequate"
    assert verdict(True, remainder) == "explained"
    standing = dataclasses.replace(remainder, beyond_noise=True)
    assert verdict(True, standing) == "partly_explained"
    assert verdict(False, standing) == "unexplained"
    as_json = result.to_dict()
    assert as_json["verdict"] == "baseline_adequate"
    assert set(as_json["remainder"]) >= {"beyond_noise", "p_value", "excess", "share_of_gap",
                                          "where", "signature"}  # fmt: skip


def test_the_remainder_is_fitted_in_the_units_of_the_model_s_miss(
    stand: StandConfig, clean_heavy: list[Trace]
) -> None:
    # A model that misses u far more than F (its u 5 % short, as a dial gauge reading
    # long would leave it): fitted in noise units pooled over the samples, every kind gave
    # up F, the channel the model meets, for u, though the held-out error pools the
    # channels as a geometric mean. In the units of the model's miss none takes F's
    # held-out error past the model's by more than a tenth, and the best lowers the pooled
    # error (``other``, the training cycles' mean, is no fit: it carries their noise in
    # both channels alike).
    nominal = stand.stand_params("final", HEAVY)
    values = fit(Candidate.build(), clean_heavy, nominal).values
    right = outputs_of(Candidate.build(), values, clean_heavy, nominal)
    short = [dataclasses.replace(o, u_m=0.95 * o.u_m) for o in right]
    f_before = heldout_excess(clean_heavy, short, ("F",))
    assert heldout_excess(clean_heavy, short, ("u",)) > 20 * f_before
    fitted = [
        k for k in fit_signatures(clean_heavy, short, nominal, values, True) if k.kind != "other"
    ]
    for kind in fitted:
        assert heldout_excess(clean_heavy, kind.outputs, ("F",)) < 1.1 * f_before, kind.name
    pooled = heldout_excess(clean_heavy, short)
    assert min(heldout_excess(clean_heavy, kind.outputs) for kind in fitted) < 0.97 * pooled
    in_noise = fit_signatures(clean_heavy, short, nominal, values)
    least = min(
        heldout_excess(clean_heavy, kind.outputs, ("F",))
        for kind in in_noise
        if kind.kind != "other"
    )
    assert least > 2 * f_before  # what the noise units did: every kind gave up F


def test_a_kind_must_gain_beyond_the_baseline_s_own_terms(
    stand: StandConfig, clean_heavy: list[Trace]
) -> None:
    # Every kind is fitted beside the baseline's own terms (k·e, c·ė, friction). Judged
    # against the model, a model 1 % too stiff let every kind pass on what those terms
    # gain alone; judged against them refitted alone, a drift, a velocity law or a
    # position term adds nothing and does not pass.
    nominal = stand.stand_params("final", HEAVY)
    values = fit(Candidate.build(), clean_heavy, nominal).values
    stiff = {**values, "stiffness_scale": 1.01 * values["stiffness_scale"]}
    outputs = outputs_of(Candidate.build(), stiff, clean_heavy, nominal)

    def passing(beyond: bool) -> set[str]:
        signatures, _, _ = judge_signatures(
            clean_heavy, outputs, nominal, stiff, in_miss_units=True, beyond_baseline_terms=beyond
        )
        return {s.kind for s in signatures if s.passes and s.kind != "other"}

    assert passing(False) >= {"position", "velocity", "drift", "strain", "resonance"}
    assert not passing(True) & {"position", "velocity", "drift"}


def test_signatures_are_judged_as_a_family_against_the_model(
    stand: StandConfig, clean_heavy: list[Trace]
) -> None:
    # On a right model no kind passes, and each kind's p-value is a family one (≥ the
    # single test's), so the false-alarm rate over the kinds is the decision's ALPHA.
    nominal = stand.stand_params("final", HEAVY)
    result = diagnose(clean_heavy, nominal, CANDIDATES)
    signatures, fits, evidence = judge_signatures(
        clean_heavy, result.outputs_after, nominal, result.baseline
    )
    assert {f"{s.kind} in {s.channel}" for s in signatures} == set(fits)
    assert not any(s.passes for s in signatures)
    for s in signatures:
        ev = evidence[f"{s.kind} in {s.channel}"]
        assert ev.p_family is not None
        assert ev.p_family >= ev.p_value - 1e-12


@pytest.mark.parametrize(
    ("truth", "kind"),
    [("guide_drag", "velocity"), ("fibre_strain_stiffening", "strain"),
     ("anchor_resonance", "resonance")],
)  # fmt: skip
def test_an_effect_outside_the_catalogue_is_unexplained_and_described_by_its_kind(
    stand: StandConfig, truth: str, kind: str
) -> None:
    # Drawn from the other stand's outside effects (seed 1, the heavy weight: drag
    # 27 N·s/m and 10 N·s²/m², stiffening h 0.09, a 56 Hz anchor mode; two recordings):
    # the candidates may close some of it, but the answer is the remainder's kind.
    traces = _outside(stand, truth, HEAVY, 1)
    result = diagnose(traces, stand.stand_params("final", HEAVY), CANDIDATES)
    assert result.verdict == "unexplained"
    assert result.effects == []
    assert result.remainder is not None
    best = next(s for s in result.remainder.signature if s.passes)
    assert best.kind == kind
    assert best.closes > 0.1


@pytest.mark.parametrize("seed", [1, 2])
def test_a_single_effect_of_another_form_names_no_second_effect(
    stand: StandConfig, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The other stand's dial gauge (seed 1, light weight): gain 1.034 with a curvature
    # and 9 µm of backlash, which our gauge candidate lacks. A time skew soaked up the
    # backlash as a second effect; a quadratic term of the library did as well, so it
    # was set aside. With the starts refined by both gauges over each warm-up (the
    # backlash no longer moves them), the skew does not pass its own test. Judged with
    # every candidate, as the diagnosis runs: among these three alone the skew passes
    # in F, which the gauge's forms do not reach, by 1.05 → 1.00 noise units (p 0.017).
    # Seed 2 (gain 1.014, curvature, 13 µm of backlash): a Maxwell branch, acting through the
    # weight's motion, fitted the gauge's remainder in u better than a position or a
    # velocity term in u alone (X 3.02 against 4.25), not than both together (3.30).
    # A further effect set aside is not polished first (its polish would be spent on a
    # fit the answer drops).
    rng = CaseSpec("dial_gauge_calibration", LIGHT, 0, seed).rng()
    traces, _, _ = make_campaign(
        stand, "dial_gauge_calibration", LIGHT, rng, truth_stand="other",
        other_campaign=recording_set("moderate", stand),
    )  # fmt: skip
    polished: list[str] = []
    real_polish = naming.polish

    def polish_seen(fitted: Fitted, *args: Any) -> Fitted:
        polished.append(fitted.result.candidate.effects[-1])
        return real_polish(fitted, *args)

    monkeypatch.setattr(naming, "polish", polish_seen)
    result = diagnose(traces, stand.stand_params("final", LIGHT))
    assert [e.effect for e in result.effects] == ["dial_gauge_calibration"]
    assert not set(polished) & set(result.displaced)
