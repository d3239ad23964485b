"""Parameters per recording: do the recordings agree, and if not, what moves with what.

The paper's authors tuned stiffness, damping and friction per situation by hand and saw
them differ between quick and slow tests without knowing whether the difference was
real. Here each recording is fitted alone (from the campaign's optimum, a short local
fit), with intervals (``intervals``), and for each parameter a test says whether the
recordings' values agree within them: Cochran's Q, Σ wᵢ(θᵢ − θ̄)² with wᵢ = 1/seᵢ², on
recordings − 1 degrees of freedom, the seᵢ widened as the intervals are (Student t on
each fit's blocks), in the optimiser's coordinates (log for the scales). Where they do
not agree, a weighted regression on what the recordings differ in — drive rate, stroke,
mass — says which one the parameter follows, and what that points to.

The baseline alone is fitted per recording as well when effects are named: a stiffness
that rises with the drive rate in the baseline alone and not once the named relaxation
branch is in the model is the branch's fingerprint, and the answer to the paper's
question.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats

from sim.identify.candidates import FreeParam
from sim.identify.fitting import Candidate, fit
from sim.identify.intervals import ParameterIntervals, parameter_intervals
from sim.identify.side_by_side import in_lanes
from sim.identify.traces import Trace
from sim.params import StandParams

#: Family-wise rate of the consistency tests (over the parameters tested).
CONSISTENCY_ALPHA = 0.05
#: Local-fit evaluations per recording (as a candidate's short refit).
EVALUATIONS = 15
FTOL = 1e-3
#: The baseline alone's ranges per recording: a decade beyond the catalogue's on each side.
#: The catalogue's ranges are where a stand that lacks no effect may lie (±25 % drawn);
#: what a recording asks of the baseline where an effect is missing can lie far outside
#: (a Maxwell branch of 20 kN/m and 30 ms is ×20 the fibre's damping), and a parameter
#: pinned at a bound in every recording hides the trend this fit is there to show.
WIDENED = 10.0
#: What the recordings differ in: (key, words, unit).
COVARIATES = (("drive_rate_hz", "drive rate", "Hz"), ("stroke_m", "stroke", "m"),
              ("mass_kg", "mass", "kg"))  # fmt: skip
#: What a parameter moving with a covariate points to: (parameter, covariate, sign).
POINTS_TO = {
    ("stiffness_scale", "drive_rate_hz", 1): (
        "a relaxation branch in the fibre (fibre_viscoelastic): stiffer the quicker it is pulled"
    ),
    ("damping_scale", "drive_rate_hz", -1): (
        "damping that falls with frequency, as a relaxation branch's does (fibre_viscoelastic)"
    ),
    ("stiffness_scale", "stroke_m", 1): "a fibre that stiffens with strain (a nonlinear law)",
    ("stiffness_scale", "stroke_m", -1): (
        "a relaxation branch that relaxes through a long stroke (fibre_viscoelastic), "
        "a fibre that softens with strain, or a slipping clamp"
    ),
    ("friction_scale", "drive_rate_hz", 1): "friction that grows with speed (a drag term)",
    ("friction_scale", "drive_rate_hz", -1): "friction that falls with speed (stick-slip)",
    ("friction_scale", "mass_kg", 1): "friction that grows with load (side-load friction)",
}


@dataclass(frozen=True)
class RecordingFit:
    """One recording's own fit: values, intervals, and what its motion was."""

    name: str
    values: dict[str, float]
    sure: ParameterIntervals
    drive: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        """JSON: params, intervals, reaches_bound and the drive's rate, stroke and mass."""
        return {
            "params": self.values,
            "intervals": {k: [lo, hi] for k, (lo, hi) in self.sure.intervals.items()},
            "reaches_bound": self.sure.reaches_bound,
            **self.drive,
        }


def drive_of(trace: Trace) -> dict[str, float]:
    """What a recording's motion was: its rate, stroke, and the weight's mass.

    The rate is the drive motion's rms frequency, √(mean ẋ² / mean (x − x̄)²) / 2π over
    the cycles: how quickly the fibre is strained, whatever the stroke (a rectangle's
    steep ramps count as quick, as they are for a relaxation branch). For a sine it is
    the sine's frequency.
    """
    inside = trace.cycle >= 0
    x = trace.x_m[inside]
    if x.size < 3:
        return {"drive_rate_hz": 0.0, "stroke_m": trace.stroke_m, "mass_kg": trace.mass_kg}
    speed = np.gradient(x, 1.0 / trace.rate_hz)
    spread = float(np.mean((x - x.mean()) ** 2))
    rate = math.sqrt(float(np.mean(speed**2)) / spread) / (2 * math.pi) if spread > 0 else 0.0
    return {"drive_rate_hz": rate, "stroke_m": trace.stroke_m, "mass_kg": trace.mass_kg}


def widened_baseline() -> Candidate:
    """The baseline with its scales' ranges widened (``WIDENED``), for the per-recording fit.

    A scale's range widens by the factor on a log scale; friction's (linear, from zero)
    upwards only.
    """
    params = [
        FreeParam(p.name, p.low / WIDENED, p.high * WIDENED, p.scale)
        if p.scale == "log"
        else FreeParam(p.name, p.low, p.high * WIDENED, p.scale)
        for p in Candidate.build().params
    ]
    return Candidate((), params)


def fit_each(
    candidate: Candidate, values: dict[str, float], traces: Sequence[Trace], nominal: StandParams
) -> tuple[list[RecordingFit], int]:
    """Each recording fitted alone from the campaign's values, with its intervals."""

    def fit_one(k: int) -> tuple[RecordingFit, int]:
        tr = traces[k]
        res = fit(candidate, [tr], nominal, baseline=values, single_start=True,
                  max_nfev=EVALUATIONS, ftol=FTOL)  # fmt: skip
        sure = parameter_intervals(candidate, res.values, [tr], nominal)
        sims = res.evaluations + sure.simulations
        return RecordingFit(tr.name, res.values, sure, drive_of(tr)), sims

    # Side by side, the longest recording first (the numbers are those of one after the other).
    done = in_lanes(fit_one, [tr.samples for tr in traces])
    return [f for f, _ in done], sum(s for _, s in done)


def _internal(candidate: Candidate, name: str, value: float) -> float:
    p = next(p for p in candidate.params if p.name == name)
    return p.clipped(value)


def consistency(candidate: Candidate, fits: Sequence[RecordingFit]) -> dict[str, dict[str, Any]]:
    """Per fitted parameter: do the recordings agree (p_value), and if not, the trend.

    ``{parameter: {"p_value": p, "trend": words or None, "moves_with": covariate or None,
    "points_to": words or None}}``; p-values are Bonferroni-corrected over the parameters.
    """
    names = [n for n in fits[0].sure.internal_se if all(n in f.sure.internal_se for f in fits)]
    out: dict[str, dict[str, Any]] = {}
    if len(fits) < 2:
        return out
    for name in names:
        theta = np.array([_internal(candidate, name, f.values[name]) for f in fits])
        se = np.array([f.sure.internal_se[name] * f.sure.widening for f in fits])
        # A recording that cannot tell a parameter (no interval) carries no weight.
        w = np.where(np.isfinite(se) & (se > 0), 1.0 / np.maximum(se, 1e-300) ** 2, 0.0)
        if np.count_nonzero(w) < 2:
            continue
        mean = float(np.sum(w * theta) / np.sum(w))
        q = float(np.sum(w * (theta - mean) ** 2))
        p = min(1.0, float(stats.chi2.sf(q, np.count_nonzero(w) - 1)) * len(names))
        entry: dict[str, Any] = {"p_value": p, "trend": None, "moves_with": None, "points_to": None}
        fitted = next(par for par in candidate.params if par.name == name)
        if all(fitted.at_bound(f.values[name]) for f in fits):
            # Pinned: agreement says nothing, but every recording wants more than the range.
            entry["trend"] = f"{name} at the end of its range in every recording"
            entry["points_to"] = "more than the model's range allows: an effect it lacks"
        elif p < CONSISTENCY_ALPHA:
            entry.update(_trend(name, theta, w, fits))
        out[name] = entry
    return out


def _trend(
    name: str, theta: np.ndarray, w: np.ndarray, fits: Sequence[RecordingFit]
) -> dict[str, Any]:
    """What the parameter follows (weighted regression on each covariate alone).

    A few recordings often differ in several things at once (the paper's quick tests are
    short strokes, its slow ones long): every covariate that explains the spread is
    named, best first, and so is what each points to — the recordings cannot say which.
    """
    found: list[tuple[float, str, float]] = []
    tried = 0
    for key, _, _ in COVARIATES:
        x = np.array([f.drive[key] for f in fits])
        xm = float(np.sum(w * x) / np.sum(w))
        sxx = float(np.sum(w * (x - xm) ** 2))
        if not sxx > 1e-12 * float(np.sum(w * x**2) + 1e-300):
            continue  # the recordings do not differ in it
        tried += 1
        slope = float(np.sum(w * (x - xm) * theta) / sxx)
        found.append((float(2 * stats.norm.sf(abs(slope) * math.sqrt(sxx))), key, slope))
    found = sorted(f for f in found if f[0] * tried < CONSISTENCY_ALPHA)
    if not found:
        return {
            "trend": f"{name} differs between recordings, following none of rate, stroke or mass"
        }
    words = {k: w_ for k, w_, _ in COVARIATES}
    units = {k: u for k, _, u in COVARIATES}
    parts = [
        f"{'rises' if slope > 0 else 'falls'} with {words[key]} (p {p * tried:.2g})"
        for p, key, slope in found
    ]
    trend = f"{name} " + " and ".join(parts)
    if len(found) > 1:
        trend += ": these recordings do not tell them apart"
    pointers = [POINTS_TO.get((name, key, 1 if slope > 0 else -1)) for _, key, slope in found]
    _, key, slope = found[0]
    return {
        "trend": trend,
        "moves_with": key,
        "also_with": [k for _, k, _ in found[1:]],
        "slope_per_unit": slope,
        "unit": units[key],
        "points_to": "; or ".join(p for p in pointers if p) or None,
    }


def per_recording_report(
    candidate: Candidate,
    values: dict[str, float],
    baseline_values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
) -> tuple[dict[str, dict[str, Any]], dict[str, dict[str, Any]], dict[str, dict[str, Any]], int]:
    """The final model and (where effects are named) the baseline alone, per recording.

    Returns ``per_recording`` (JSON), the final model's consistency, the baseline
    alone's, and the simulations spent.
    """
    fits, sims = fit_each(candidate, values, traces, nominal)
    table = {f.name: f.to_dict() for f in fits}
    agree = consistency(candidate, fits)
    if not candidate.effects:
        return table, agree, agree, sims
    base = widened_baseline()
    alone, more = fit_each(base, baseline_values, traces, nominal)
    for f in alone:
        own = f.to_dict()
        table[f.name]["baseline_alone"] = {k: own[k] for k in ("params", "intervals")}
    return table, agree, consistency(base, alone), sims + more
