"""How sure: intervals of the fitted parameters and the gap, and the per-recording fits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from drivers.signals import plan_motion
from labstand.commands.diagnose import _print_summary
from sim.checks.check import CaseSpec, make_campaign, recording_set
from sim.checks.summaries import covered_truth
from sim.config import StandConfig
from sim.effects import EffectSpec
from sim.effects.realism import MeasurementNoise, NoiseSpec
from sim.identify import diagnose, make_trace
from sim.identify.fitting import Candidate, simulate_values
from sim.identify.heldout import BLOCK_S, Outputs, channel_gap
from sim.identify.intervals import (
    ParameterIntervals,
    combined_error,
    estimator_spread,
    gap_intervals,
    parameter_intervals,
    sandwich_covariance,
)
from sim.identify.per_recording import RecordingFit, consistency, drive_of, widened_baseline
from sim.identify.replicates import reading_step, residual_replicates, smooth_weights
from sim.identify.traces import Trace
from sim.model import Model
from sim.params import StandParams
from sim.situations import SITUATIONS

HEAVY = 8.131


def test_the_sandwich_covers_a_slope_under_errors_correlated_within_blocks() -> None:
    # y = a + b·t with errors that share a random level within each block (what a slack
    # event or a misfit stretch does to a fit's residuals): the least-squares slope's
    # naive standard error is too small, the cluster-robust one is not.
    rng = np.random.default_rng(1)
    blocks, per_block, truth = 24, 40, np.array([0.5, 2.0])
    t = np.linspace(0.0, 1.0, blocks * per_block)
    jac = np.column_stack([np.ones_like(t), t])
    labels = np.repeat(np.arange(blocks), per_block)
    q = float(stats.t.ppf(0.975, blocks - 1))
    naive_hits, robust_hits, trials = 0, 0, 400
    for _ in range(trials):
        noise = rng.normal(0, 1.0, blocks)[labels] + rng.normal(0, 0.3, t.size)
        y = jac @ truth + noise
        coef, *_ = np.linalg.lstsq(jac, y, rcond=None)
        residuals = jac @ coef - y
        cov, g = sandwich_covariance(jac, residuals, labels)
        assert g == blocks
        naive = np.linalg.inv(jac.T @ jac) * residuals.var()
        naive_hits += abs(coef[1] - truth[1]) <= 1.96 * math.sqrt(naive[1, 1])
        robust_hits += abs(coef[1] - truth[1]) <= q * math.sqrt(cov[1, 1])
    assert robust_hits / trials >= 0.9
    assert naive_hits / trials < 0.6  # the correlation is real: ignoring it misleads


def _heavy_none(
    stand: StandConfig, seed: int, first: int
) -> tuple[list[Trace], dict[str, float], StandParams]:
    """Heavy `none`, moderate recordings from ``first`` on: traces, truth, nominal."""
    recordings = recording_set("moderate", stand)[first:]
    spec = CaseSpec("none", HEAVY, 0, seed)
    traces, _, truth = make_campaign(stand, "none", HEAVY, spec.rng(), recordings)
    return traces, truth, stand.stand_params("final", HEAVY)


def test_baseline_intervals_hold_the_drawn_stand_and_widen_with_the_noise(
    stand: StandConfig,
) -> None:
    traces, truth, nominal = _heavy_none(stand, 3, 2)
    quiet = parameter_intervals(Candidate.build(), truth, traces, nominal)
    for name in ("stiffness_scale", "damping_scale", "friction_scale"):
        lo, hi = quiet.intervals[name]
        assert lo <= truth[name] <= hi, name
    # The same campaign with ten times the force noise: every interval is wider.
    rng = np.random.default_rng(0)
    noisy = []
    for tr in traces:
        extra = rng.normal(0.0, 10 * tr.noise_force_n, tr.samples)
        t = np.arange(tr.samples) / tr.rate_hz
        noisy.append(make_trace(tr.name, t, tr.x_m, tr.u_m, tr.force_n + extra, tr.mass_kg))
    loud = parameter_intervals(Candidate.build(), truth, noisy, nominal)
    for name, (lo, hi) in quiet.intervals.items():
        low, high = loud.intervals[name]
        assert high - low > hi - lo, name


def _model(rng: np.random.Generator, trace: Trace, noise_units: float) -> Outputs:
    """Outputs off the recording by ``noise_units`` of each channel's noise."""
    u = trace.u_m + rng.normal(0.0, noise_units * trace.noise_u_m, trace.samples)
    f = trace.force_n + rng.normal(0.0, noise_units * trace.noise_force_n, trace.samples)
    return Outputs(u, f)


def test_gap_intervals_hold_the_point_figures_and_narrow_with_more_cycles(
    stand: StandConfig,
) -> None:
    recordings = recording_set("moderate", stand)
    spec = CaseSpec("none", HEAVY, 0, 4)
    traces, _, _ = make_campaign(stand, "none", HEAVY, spec.rng(), recordings)
    rng = np.random.default_rng(2)
    before = [_model(rng, t, 5.0) for t in traces]
    after = [_model(rng, t, 1.0) for t in traces]
    gaps, closure = gap_intervals(traces, before, after)
    point_before, point_after = channel_gap(traces, before), channel_gap(traces, after)
    for ch in ("u", "F"):
        lo, hi = gaps["before"][ch]
        assert lo <= point_before[ch]["nrmse"] <= hi
        lo, hi = gaps["after"][ch]
        assert lo <= point_after[ch]["nrmse"] <= hi
    # Errors of five noise units cut to one (plus the noise itself): about all the gap
    # above the noise is closed (a little more where the noise read low), and the
    # interval says so.
    assert closure is not None
    assert closure[0] > 0.8 and closure[1] < 1.1
    _, fewer = gap_intervals(traces[:1], before[:1], after[:1])
    assert fewer is not None
    assert fewer[1] - fewer[0] > closure[1] - closure[0]


def _fit(name: str, rate: float, stiffness: float, se: float) -> RecordingFit:
    sure = ParameterIntervals(internal_se={"stiffness_scale": se, "damping_scale": se})
    values = {"stiffness_scale": stiffness, "damping_scale": 1.0, "friction_scale": 1.0}
    drive = {"drive_rate_hz": rate, "stroke_m": 0.03, "mass_kg": HEAVY}
    return RecordingFit(name, values, sure, drive)


def test_consistency_flags_a_stiffness_that_rises_with_the_drive_rate() -> None:
    base = Candidate.build()
    rising = [_fit(f"r{k}", r, math.exp(0.05 * r), 0.01) for k, r in enumerate((0.4, 1, 2, 3))]
    verdict = consistency(base, rising)["stiffness_scale"]
    assert verdict["p_value"] < 0.01
    assert verdict["moves_with"] == "drive_rate_hz"
    assert "relaxation branch" in verdict["points_to"]
    # The same spread with intervals ten times wider: the recordings agree.
    vague = [_fit(f.name, f.drive["drive_rate_hz"], f.values["stiffness_scale"], 0.1)
             for f in rising]  # fmt: skip
    assert consistency(base, vague)["stiffness_scale"]["moves_with"] is None
    assert consistency(base, vague)["damping_scale"]["p_value"] == pytest.approx(1.0)
    # Every recording at the range's end (a branch stiffer than the baseline may be):
    # agreement means nothing there, and the answer says the range is too small.
    pinned = [_fit(f.name, f.drive["drive_rate_hz"], 2.0, 0.01) for f in rising]
    verdict = consistency(base, pinned)["stiffness_scale"]
    assert verdict["moves_with"] is None and "end of its range" in verdict["trend"]


def test_the_drive_rate_of_a_sine_is_its_frequency(stand: StandConfig) -> None:
    rate = 2000.0
    t = np.arange(int(6 * rate)) / rate
    x = 0.02 * np.sin(2 * np.pi * 1.5 * t)
    trace = make_trace("sine", t, x, 1e-3 * x, 50 + 100 * x, HEAVY)
    assert drive_of(trace)["drive_rate_hz"] == pytest.approx(1.5, rel=0.02)


def test_a_diagnosis_reports_intervals_that_hold_its_numbers(
    stand: StandConfig, capsys: pytest.CaptureFixture[str]
) -> None:
    recordings = recording_set("moderate", stand)[2:]
    spec = CaseSpec("fibre_viscoelastic", HEAVY, 0, 2)
    traces, _, truth = make_campaign(stand, spec.truth, HEAVY, spec.rng(), recordings)
    nominal = stand.stand_params("final", HEAVY)
    d = diagnose(traces, nominal, candidates=["fibre_viscoelastic", "channel_time_skew"])
    assert [a.effect for a in d.effects] == ["fibre_viscoelastic"]
    assert set(d.baseline_intervals) == {"stiffness_scale", "damping_scale", "friction_scale"}
    for name, value in d.baseline.items():
        lo, hi = d.baseline_intervals[name]
        assert lo <= value <= hi
    (effect,) = d.effects
    assert set(effect.intervals) == set(effect.params)
    assert d.gap_closure_interval is not None
    lo, hi = d.gap_closure_interval
    assert lo <= d.gap_closure <= hi
    # Every recording fitted alone, with its drive, and a consistency entry per parameter.
    assert set(d.per_recording) == {t.name for t in traces}
    assert set(d.consistency) >= {"stiffness_scale", "fibre_viscoelastic.relaxation_time_s"}
    held = covered_truth(d, spec.truth, truth)
    assert set(held) >= {"stiffness_scale", "fibre_viscoelastic.relaxation_time_s"}
    # The CLI's summary shows each number with its interval.
    _print_summary(d, None)
    text = capsys.readouterr().out
    lo, hi = d.baseline_intervals["stiffness_scale"]
    assert f"stiffness_scale = {d.baseline['stiffness_scale']:.4g} [{lo:.4g}, {hi:.4g}]" in text
    lo, hi = effect.intervals["relaxation_time_s"]
    assert f"relaxation_time_s = {effect.params['relaxation_time_s']:.4g} [{lo:.4g}, " in text
    assert "Gap closed: " in text and "95 % interval" in text
    payload = d.to_dict()
    assert payload["effects"][0]["intervals"]["relaxation_time_s"] == list(
        effect.intervals["relaxation_time_s"]
    )


def test_the_papers_situations_with_a_relaxation_branch_need_their_own_stiffness(
    stand: StandConfig,
) -> None:
    # The paper tuned the stiffness per situation and found quick and slow tests wanting
    # different values. Its four heavy-weight situations simulated with a Maxwell branch
    # in the fibre: the baseline alone fitted per recording disagrees, the quick tests
    # stiffer; with the branch named, the recordings agree.
    rng = np.random.default_rng(0)
    noise = NoiseSpec.draw(rng)
    traces = []
    for name in ("10", "11", "12a", "14"):
        s = SITUATIONS[name]
        t, x = plan_motion(s.signal, stand.drive).sample(stand.sample_rate_hz)
        model = Model(stand.stand_params("final", s.mass_kg), [EffectSpec("fibre_viscoelastic")])
        run = model.run(x, stand.sample_rate_hz)
        u, f = MeasurementNoise(noise, stand.sample_rate_hz, rng).apply(run.u_m, run.force_n)
        traces.append(make_trace(name, t, x, u, f, s.mass_kg))
    nominal = stand.stand_params("final", HEAVY)
    d = diagnose(traces, nominal, candidates=["fibre_viscoelastic", "channel_time_skew"])
    assert d.effect == "fibre_viscoelastic"
    fits = d.per_recording.items()
    alone = {n: r["baseline_alone"]["params"]["stiffness_scale"] for n, r in fits}
    quick = [n for n in alone if SITUATIONS[n].rate_class == "quicker"]
    slow = [n for n in alone if SITUATIONS[n].rate_class == "slower"]
    assert min(alone[n] for n in quick) > min(alone[n] for n in slow)
    assert np.mean([alone[n] for n in quick]) > np.mean([alone[n] for n in slow])
    assert d.baseline_consistency["stiffness_scale"]["p_value"] < 0.05
    # What explains it: the branch, named through whichever parameter carries its rate
    # dependence once each has room (the damping, falling with the rate, here).
    pointers = [v["points_to"] or "" for v in d.baseline_consistency.values()]
    assert any("fibre_viscoelastic" in text for text in pointers)
    assert d.consistency["stiffness_scale"]["p_value"] >= 0.05
    # Read off the fibre's law, the baseline alone's stiffness rises with the strain
    # rate; the named branch's model rises as the recordings do.
    assert d.dynamic_stiffness["baseline_alone"]["rises_with_rate"]
    assert d.dynamic_stiffness["final"]["explained_share"] > 0.9
    # The branch's dissipation (k₂τ ≈ 600 N·s/m) is far beyond the catalogue's damping
    # range (×4 of 27.5 N·s/m): the baseline alone's per-recording fit has room for it,
    # so its damping is a measured value, not the range's end in every recording.
    damping = [r["baseline_alone"]["params"]["damping_scale"] for _, r in fits]
    widened = next(p for p in widened_baseline().params if p.name == "damping_scale")
    assert min(damping) > 4.0
    assert not any(widened.at_bound(v) for v in damping)
    assert "at the end of its range" not in (d.baseline_consistency["damping_scale"]["trend"] or "")


def test_a_parameter_the_recordings_do_not_feel_has_no_interval(stand: StandConfig) -> None:
    # A pulley seat that never moves (step 0): where it would start and how deep it
    # sits change nothing the gauges read, so their intervals must say "anywhere in the
    # range", not "exactly known" (a pseudo-inverse would give them zero width).
    recordings = recording_set("moderate", stand)[2:]
    spec = CaseSpec("none", HEAVY, 0, 3)
    traces, _, truth = make_campaign(stand, "none", HEAVY, spec.rng(), recordings)
    nominal = stand.stand_params("final", HEAVY)
    candidate = Candidate.build("fibre_pulley_jump")
    values = {p.name: truth.get(p.name, 0.5 * (p.low + p.high)) for p in candidate.params}
    values["fibre_pulley_jump.step_m"] = 0.0
    sure = parameter_intervals(candidate, values, traces, nominal)
    for name in ("fibre_pulley_jump.depth_scale_m", "fibre_pulley_jump.onset_m"):
        p = next(p for p in candidate.params if p.name == name)
        assert sure.intervals[name] == pytest.approx((p.low, p.high)), name
        assert name in sure.reaches_bound
    lo, hi = sure.intervals["stiffness_scale"]
    assert lo <= truth["stiffness_scale"] <= hi


def test_a_spread_from_few_replicates_carries_their_degrees_of_freedom() -> None:
    # A bootstrap spread from six replicates that dominates the sandwich: five degrees of
    # freedom (and a bit more for the bias term's own share), so its t is about 2.5, not
    # the blocks' 1.97; a dominant sandwich keeps the blocks' many degrees of freedom.
    se, dof = combined_error(0.1, 200.0, 1.0, 6)
    assert se == pytest.approx(math.sqrt(1.0 + 1.0 / 6))
    assert 5.0 <= dof < 7.0
    se, dof = combined_error(1.0, 200.0, 0.01, 6)
    assert se == pytest.approx(1.0, rel=1e-4)
    assert dof > 150.0
    # Coverage: the estimate off by a normal error of unit spread, the spread estimated
    # from six draws of it: a t on the combined degrees of freedom covers at 95 %, the
    # normal quantile does not.
    rng = np.random.default_rng(3)
    hits_t = hits_z = 0
    trials = 4000
    for _ in range(trials):
        shift = rng.normal(0.0, 1.0, 6)
        miss = rng.normal(0.0, 1.0)
        se, dof = combined_error(0.01, 200.0, float(np.std(shift, ddof=1)), 6)
        hits_t += abs(miss) <= stats.t.ppf(0.975, dof) * se
        hits_z += abs(miss) <= 1.96 * se
    assert hits_t / trials >= 0.94
    assert hits_z / trials < hits_t / trials - 0.02


def _louder_after_rest(traces: list[Trace], times: float, rng: np.random.Generator) -> list[Trace]:
    """The recordings with errors ``times`` their rest noise from the first cycle on.

    The initial rest is untouched, so each trace's rest noise (what white replicates would
    draw) stays what it was.
    """
    out = []
    for tr in traces:
        after = tr.cycle >= 0
        u = tr.u_m + np.where(after, rng.normal(0.0, times * tr.noise_u_m, tr.samples), 0.0)
        f = tr.force_n + np.where(after, rng.normal(0.0, times * tr.noise_force_n, tr.samples), 0.0)
        t = np.arange(tr.samples) / tr.rate_hz
        out.append(make_trace(tr.name, t, tr.x_m, u, f, tr.mass_kg))
    return out


def test_residual_replicates_reweight_the_fits_own_errors_smoothly(stand: StandConfig) -> None:
    traces, truth, nominal = _heavy_none(stand, 5, 3)
    candidate = Candidate.build()
    (tr,) = traces
    u_fit, f_fit = (a[0] for a in simulate_values(candidate, [truth], tr, nominal))
    ((drawn,),), ((again,),) = (
        residual_replicates(candidate, truth, traces, nominal, np.random.default_rng(s), 1)
        for s in (0, 1)
    )
    # The same weight on both channels: the fit plus the residuals times it.
    weight = smooth_weights(np.random.default_rng(0), tr.samples, BLOCK_S * tr.rate_hz)
    ok = tr.present
    for got, rec, fitted, step in (
        (drawn.u_m, tr.u_m, u_fit, reading_step(tr.u_m)),
        (drawn.force_n, tr.force_n, f_fit, reading_step(tr.force_n)),
    ):
        want = fitted + weight * (rec - fitted)
        np.testing.assert_allclose(got[ok], want[ok], atol=step / 2 + 1e-12)
    assert not np.array_equal(drawn.force_n[ok], again.force_n[ok])
    assert np.array_equal(np.isnan(drawn.force_n), ~ok)  # a lost sample stays lost


def test_the_bootstrap_weights_have_unit_variance_and_no_jumps() -> None:
    span = 500.0
    w = smooth_weights(np.random.default_rng(4), 400_000, span)
    assert w.size == 400_000
    assert abs(w.mean()) < 0.05 and w.var() == pytest.approx(1.0, abs=0.05)

    def corr(lag: int) -> float:
        return float(np.corrcoef(w[:-lag], w[lag:])[0, 1])

    assert corr(int(span / 4)) > 0.7  # one stretch moves together
    assert abs(corr(int(span))) < 0.1  # a span apart, nearly independent
    # No step between neighbouring samples anywhere near a sign flip's 2.
    assert np.abs(np.diff(w)).max() < 0.05


def test_the_bootstrap_spread_follows_the_errors_in_motion_not_the_rest_noise(
    stand: StandConfig,
) -> None:
    # Errors four times the rest noise while the drive moves (a restart from a
    # noisy state, a drive read with noise): the estimator spreads about four times as
    # far. Replicates with white noise at the rest level would not see it.
    traces, truth, nominal = _heavy_none(stand, 6, 2)
    loud = _louder_after_rest(traces, 4.0, np.random.default_rng(3))
    assert [t.noise_force_n for t in loud] == pytest.approx([t.noise_force_n for t in traces])
    candidate = Candidate.build()
    quiet_shifts, _ = estimator_spread(candidate, truth, traces, nominal, replicates=8)
    loud_shifts, _ = estimator_spread(candidate, truth, loud, nominal, replicates=8)
    ratio = np.std(loud_shifts["stiffness_scale"]) / np.std(quiet_shifts["stiffness_scale"])
    assert ratio > 2.0
