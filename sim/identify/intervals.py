"""How sure: 95 % intervals of the fitted parameters and of the held-out gap.

Parameters: the fit's Gauss–Newton linearisation at its optimum with a covariance that is
robust to what these fits have — errors correlated over a stretch of samples (a slack
or snatch event moves many samples together) and a model that is never exact — the
cluster-robust "sandwich" A⁻¹BA⁻¹ over training blocks of about ``BLOCK_S`` (A = JᵀJ,
B = Σ_blocks (J_bᵀr_b)(J_bᵀr_b)ᵀ), the held-out test's unit of independence, with the
small-sample factor G/(G−1) and Student's t on G−1 degrees of freedom for G blocks.
The objective is rugged (slack and stick events switch), so its slope at the optimum is
not its slope over the distance an interval spans: the Jacobian is taken again as
secants over the interval's own half-widths until they agree (``SECANT_ROUNDS``); on a
heavy pulley's inertia the local slope made the interval 9× too narrow.

The sandwich sees the residuals' spread, not all of the estimator's: restarts from noisy
measured states move the damping by several times its standard error. A bootstrap
(``estimator_spread``: the fit repeated on ``BIAS_REPLICATES`` recordings of the fitted
model carrying the fit's own residuals times a smooth random weight: a dependent wild
bootstrap) measures the spread. Its replicates carry the errors the fit left, not
white noise at the rest level: the fit's residuals are 1.5 times the rest noise on the
quick recordings and 2.7 times on the bursts (medians over 60 same-form campaigns;
each restart starts from a measured state, a drive read with noise moves a whole
swing), and with white noise only 78 % of the same-form intervals held the truth (88 %
now). The interval is centred on the fitted value and as wide as the larger spread
(plus the uncertainty of the replicates' mean). It is not shifted by that mean: a
replicate restarts from states read in its own data, off the states its fitted run
started from, so the mean is a bias of the replicates' own. Six replicates know their
spread only to a quarter or so: its Student t has the combined error's
Welch–Satterthwaite degrees of freedom (``combined_error``), not the blocks'.

A linearisation knows the cost only near the fit. Along each parameter's profile line
(the others at their conditional optimum) the cost may rise less than the parabola
further out: a valley flatter than it, or a second one just past a low ridge (a light
pulley's inertia traded against its bearing torque, a branch's τ against the fibre's
damping). Each end then moves out to the farthest point reached without the cost passing
the parabola's rise at the end (``along_profiles``): the likelihood-ratio set at the
level the interval already has, found on one batch of simulations per parameter.

Intervals are built in the optimiser's coordinates (log for the scales, so they are
asymmetric in natural units), cut at the physical range and marked where they reach
it: there the data cannot say how far beyond the range the parameter would go. Counts
and scanned thresholds are held at their level (no derivative exists); their interval
is the level itself. They are local: a fit in a wrong basin, or a parameter traded
along a ridge with another (a pulley's inertia and its bearing friction), can lie
outside them; the held-out verdict says whether the model fits.

The gap (held-out NRMSE per channel, before and after; the share of the gap closed): a
bootstrap over held-out blocks (as the decision's test cuts them) within each recording,
no refit: the uncertainty of *how far* the gap shrinks given the fitted models.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from sim.identify.fitting import Candidate, FitResult, Objective, fit, scored_samples
from sim.identify.heldout import BLOCK_S, Outputs, _noise_scale, held_out_blocks
from sim.identify.replicates import residual_replicates
from sim.identify.report import Intervals
from sim.identify.side_by_side import in_lanes
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]

LEVEL = 0.95
#: What the report says of the method.
PARAMETER_METHOD = (
    "parameters: Gauss–Newton linearisation (secants over the interval) with a "
    "cluster-robust sandwich covariance over 0.25 s training blocks, Student t on "
    "blocks − 1 degrees of freedom, widened by a dependent wild bootstrap of the fit "
    "(its residuals times a random weight correlated over 0.25 s; Welch–Satterthwaite "
    "degrees of freedom for its few replicates), centred on the fit, each end carried "
    "out along the parameter's profile line where the training cost stays below the "
    "rise the linearisation gives at that end"
)
GAP_METHOD = "gap and closure: bootstrap over 0.25 s held-out blocks within each recording"
BOOTSTRAP_ROUNDS = 1000
#: Replicates of the bootstrap that measures the estimator's spread, and the
#: optimiser evaluations of each refit.
BIAS_REPLICATES = 6
BIAS_EVALUATIONS = 15
#: Rounds of the secant Jacobian (its steps the interval's half-widths) at most.
SECANT_ROUNDS = 3
#: How far along its profile line an interval's end may move, in its own half-widths.
PROFILE_STEPS = (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)


@dataclass
class ParameterIntervals:
    """Intervals of one fit (natural units) and which of them reach their physical bound."""

    intervals: Intervals = field(default_factory=dict)
    reaches_bound: list[str] = field(default_factory=list)
    #: Standard errors in the optimiser's coordinates (what a consistency test compares).
    internal_se: dict[str, float] = field(default_factory=dict)
    #: How much wider than a normal interval these are (Student t's quantile over the
    #: normal's): what a test of the standard errors widens them by too.
    widening: float = 1.0
    simulations: int = 0


def _block_labels(traces: Sequence[Trace], stride: int) -> NDArray[np.int64]:
    """Each residual's training block, a label unique over traces, in ``Objective``'s order.

    Blocks as the held-out test cuts them (``held_out_blocks``): each cycle (and the rest
    before the first) in pieces of about ``BLOCK_S``, whose errors are nearly independent
    of their neighbours'.
    """
    labels = []
    offset = 0
    for tr in traces:
        idx = scored_samples(tr, stride)
        own = np.zeros(idx.size, np.int64)
        for c in np.unique(tr.cycle[idx]):
            at = np.flatnonzero(tr.cycle[idx] == c)
            span = int(idx[at[-1]] - idx[at[0]]) + 1
            pieces = max(1, int(span // (BLOCK_S * tr.rate_hz)))
            for piece in np.array_split(at, pieces):
                own[piece] = offset
                offset += 1
        labels += [own, own]  # the u residuals, then the F ones
    return np.concatenate(labels) if labels else np.zeros(0, np.int64)


def sandwich_covariance(
    jac: FloatArray, residuals: FloatArray, clusters: NDArray[np.int64]
) -> tuple[FloatArray, int]:
    """Cluster-robust covariance of a least-squares fit, and the number of clusters."""
    bread = np.linalg.pinv(jac.T @ jac)
    groups = np.unique(clusters)
    scores = np.stack([jac[clusters == g].T @ residuals[clusters == g] for g in groups])
    g = groups.size
    meat = scores.T @ scores * (g / max(g - 1, 1))
    return bread @ meat @ bread, g


def combined_error(se: float, se_dof: float, spread: float, replicates: int) -> tuple[float, float]:
    """The sandwich's or the bootstrap's error (the larger) and the bias estimate's.

    Returns the combined standard error and its Welch–Satterthwaite degrees of freedom:
    a spread from a few replicates is itself uncertain (six give five degrees of
    freedom, a Student t of 2.57 rather than 1.97), which the interval must carry.
    """
    wider, wider_dof = (spread, replicates - 1.0) if spread > se else (se, se_dof)
    parts = ((wider**2, wider_dof), (spread**2 / replicates, replicates - 1.0))
    total = sum(v for v, _ in parts)
    if total <= 0.0:
        return 0.0, se_dof
    dof = total**2 / sum(v**2 / max(d, 1.0) for v, d in parts)
    return math.sqrt(total), dof


def parameter_intervals(
    candidate: Candidate,
    values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
    level: float = LEVEL,
    stride: int = 4,
    replicates: int = 0,
) -> ParameterIntervals:
    """95 % intervals of a fitted candidate's parameters (see the module docstring).

    ``replicates``: refits on recordings of the fitted model (``estimator_spread``) that
    widen the interval to the estimator's spread; 0: none.
    """
    objective = Objective(candidate, traces, nominal, stride)
    z = candidate.internal(values)
    free = np.array([p.held is None and not p.integer and not p.scan for p in candidate.params])
    out = ParameterIntervals()
    for p, fixed in zip(candidate.params, ~free, strict=True):
        if fixed and p.name in values:
            out.intervals[p.name] = (values[p.name], values[p.name])
    if not free.any():
        return out
    residuals = objective.residuals(z)
    labels = _block_labels(traces, stride)
    lo_all = np.array([p.bounds()[0] for p in candidate.params])
    hi_all = np.array([p.bounds()[1] for p in candidate.params])
    steps = 1e-3 * (hi_all - lo_all)
    for _ in range(SECANT_ROUNDS):
        jac = objective.jacobian(z, free, steps)
        cov, clusters = sandwich_covariance(jac, residuals, labels)
        t = float(stats.t.ppf(0.5 + level / 2, max(clusters - 1, 1)))
        se_free = np.sqrt(np.maximum(np.diag(cov), 0.0))
        # A parameter the outputs do not feel (its effect idle on these recordings) is
        # not known at all: the pseudo-inverse would call it exact.
        feel = np.linalg.norm(jac, axis=0)
        se_free[feel <= 1e-9 * max(float(feel.max()), 1e-300)] = math.inf
        # The next slopes are secants over the interval itself (at least the fit's step,
        # at most half the range): a rugged objective's local slope is not the slope
        # over the distance the interval claims.
        wanted = np.clip(np.nan_to_num(t * se_free, posinf=np.inf), steps[free],
                         0.5 * (hi_all - lo_all)[free])  # fmt: skip
        if np.allclose(wanted, steps[free], rtol=0.25):
            break
        steps[free] = wanted
    shifts: dict[str, FloatArray] = {}
    if replicates:
        shifts, sims = estimator_spread(candidate, values, traces, nominal, replicates)
        out.simulations += sims
    out.simulations += objective.simulations
    out.widening = t / float(stats.norm.ppf(0.5 + level / 2))
    free_params = [p for p, f in zip(candidate.params, free, strict=True) if f]
    ends: dict[str, tuple[float, float]] = {}
    for k, p in enumerate(free_params):
        se = float(se_free[k])
        zk = p.clipped(values[p.name])
        shift = shifts.get(p.name)
        t_k = t
        if shift is not None and shift.size > 1:
            # As wide as the larger of the two spreads plus what the replicates' mean
            # could not rule out. Centred on the fit, not shifted by that mean: each
            # replicate restarts from states read in its own data, (w − 1)·r off the
            # states its fitted run started from, so the mean holds a bias of the
            # replicates' own (shifted, 256/300 held the truth on seeds 6–8; centred,
            # 265/300; seeds 1–2: 168/198 against 181/198).
            spread = float(np.std(shift, ddof=1))
            se, dof = combined_error(se, max(clusters - 1, 1), spread, shift.size)
            t_k = float(stats.t.ppf(0.5 + level / 2, dof))
        lo, hi = p.bounds()
        out.internal_se[p.name] = se
        ends[p.name] = (max(zk - t_k * se, lo), min(zk + t_k * se, hi))
    ends, sims = along_profiles(objective, candidate, z, free, ends)
    out.simulations += sims
    for p in free_params:
        lo, hi = p.bounds()
        z_lo, z_hi = ends[p.name]
        out.intervals[p.name] = (p.to_natural(z_lo), p.to_natural(z_hi))
        edge = 2e-3 * (hi - lo)
        if z_lo <= lo + edge or z_hi >= hi - edge:
            out.reaches_bound.append(p.name)
    return out


def along_profiles(
    objective: Objective,
    candidate: Candidate,
    z: FloatArray,
    free: NDArray[np.bool_],
    ends: dict[str, tuple[float, float]],
) -> tuple[dict[str, tuple[float, float]], int]:
    """Each interval's ends carried out along its profile where the cost stays as low.

    Along the Gauss–Newton profile line of a parameter (the others at their conditional
    optimum, d = Σe_k/Σ_kk, Σ = (JᵀJ)⁻¹ with J the secants over the interval), the local
    quadratic says how far the training cost rises at the interval's end. Where the real
    cost rises less than that further out (a valley flatter than a parabola: a pulley's
    inertia traded against its bearing torque, a branch's τ against the fibre's
    damping), the end moves out to the farthest of ``PROFILE_STEPS`` interval
    half-widths reached without the cost passing that rise: the likelihood-ratio set at
    the level the interval already has. Never narrows. ``ends``: per free parameter, the
    interval in the optimiser's coordinates. Returns the new ends and the simulations.
    """
    params = [p for p, f in zip(candidate.params, free, strict=True) if f]
    known = [
        k for k, p in enumerate(params)
        if p.name in ends and all(math.isfinite(v) for v in ends[p.name])
    ]  # fmt: skip
    if not known:
        return ends, 0
    lo_all = np.array([p.bounds()[0] for p in candidate.params])
    hi_all = np.array([p.bounds()[1] for p in candidate.params])
    steps = 1e-3 * (hi_all - lo_all)
    half = np.array([0.5 * (ends[p.name][1] - ends[p.name][0]) if k in known else 0.0
                     for k, p in enumerate(params)])  # fmt: skip
    steps[free] = np.clip(half, steps[free], 0.5 * (hi_all - lo_all)[free])
    sims = objective.simulations
    jac = objective.jacobian(z, free, steps)
    base = objective.residuals(z)
    cost0 = float(base @ base)
    sigma = np.linalg.pinv(jac.T @ jac)
    out = dict(ends)
    for k in known:
        p = params[k]
        if not sigma[k, k] > 0:
            continue
        direction = np.zeros(z.size)
        direction[free] = sigma[:, k] / sigma[k, k]
        zk = float(z[candidate.params.index(p)])
        new = list(ends[p.name])
        for side in (0, 1):
            reach = ends[p.name][side] - zk
            if reach == 0.0:
                continue
            rise = float(np.sum((jac @ (direction[free] * reach)) ** 2))
            line = np.array([np.clip(z + m * reach * direction, lo_all, hi_all)
                             for m in PROFILE_STEPS])  # fmt: skip
            costs = np.sum(objective.residuals_batch(line) ** 2, axis=1) - cost0
            farthest = 1.0
            for m, cost in zip(PROFILE_STEPS, costs, strict=True):
                if not cost <= rise:
                    break
                farthest = m
            lo, hi = p.bounds()
            new[side] = min(max(zk + farthest * reach, lo), hi)
        out[p.name] = (min(new), max(new))
    return out, objective.simulations - sims


def estimator_spread(
    candidate: Candidate,
    values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
    replicates: int = BIAS_REPLICATES,
    seed: int = 0,
) -> tuple[dict[str, FloatArray], int]:
    """The fit repeated on recordings of the fitted model (``residual_replicates``).

    Returns, per fitted parameter, the replicates' estimates minus the fitted value in
    the optimiser's coordinates (their spread: what the sandwich does not see of
    restarts from noisy measured states and a drive read with noise), and the
    simulations spent. Each refit is local, from the fitted
    values, converged further than a diagnosis's short refit so that it reaches its own
    optimum.
    """
    rng = np.random.default_rng(seed)
    fitted = {p.name: p.clipped(values[p.name]) for p in candidate.params if p.name in values}
    shifts: dict[str, list[float]] = {}
    sims = len(traces)
    drawn = residual_replicates(candidate, values, traces, nominal, rng, replicates)

    def refit(k: int) -> FitResult:
        return fit(candidate, drawn[k], nominal, baseline=values, single_start=True,
                   max_nfev=BIAS_EVALUATIONS)  # fmt: skip

    # Side by side: the replicates are drawn first, so the numbers do not depend on it.
    for res in in_lanes(refit, [1.0] * len(drawn)):
        sims += res.evaluations
        for p in candidate.params:
            if p.name in fitted and p.held is None and not p.scan:
                shifts.setdefault(p.name, []).append(p.clipped(res.values[p.name]) - fitted[p.name])
    return {k: np.asarray(v) for k, v in shifts.items()}, sims


@dataclass(frozen=True)
class _BlockSums:
    """Per held-out block of one trace and channel: what an NRMSE and an excess add up."""

    n: FloatArray
    rec: FloatArray
    rec2: FloatArray
    err_before: FloatArray
    err_after: FloatArray
    scale: float


def _block_sums(trace: Trace, before: Outputs, after: Outputs) -> list[_BlockSums]:
    """For u and F: sums over each held-out block of the trace."""
    idx = trace.test
    sel = held_out_blocks(trace)
    sums = []
    for rec, b, a, noise in (
        (trace.u_m, before.u_m, after.u_m, trace.noise_u_m),
        (trace.force_n, before.force_n, after.force_n, trace.noise_force_n),
    ):
        sums.append(
            _BlockSums(
                np.array([s.size for s in sel], float),
                np.array([rec[s].sum() for s in sel]),
                np.array([(rec[s] ** 2).sum() for s in sel]),
                np.array([((b[s] - rec[s]) ** 2).sum() for s in sel]),
                np.array([((a[s] - rec[s]) ** 2).sum() for s in sel]),
                _noise_scale(rec[idx], noise),
            )
        )
    return sums


def gap_intervals(
    traces: Sequence[Trace],
    before: Sequence[Outputs],
    after: Sequence[Outputs],
    level: float = LEVEL,
    rounds: int = BOOTSTRAP_ROUNDS,
    seed: int = 0,
) -> tuple[dict[str, Intervals], tuple[float, float] | None]:
    """Bootstrap intervals of each channel's held-out NRMSE (before, after) and the closure.

    The closure is the share of the gap above the noise that the named effects close,
    (X_before − X_after) / (X_before − 1) with X the held-out excess (``heldout_excess``).
    """
    rng = np.random.default_rng(seed)
    per_trace = [_block_sums(tr, b, a) for tr, b, a in zip(traces, before, after, strict=True)]
    if not per_trace or any(s[0].n.size == 0 for s in per_trace):
        return {}, None
    # Resample each trace's held-out blocks: weights (rounds, blocks) of draw counts.
    weights = [
        np.stack([np.bincount(row, minlength=s[0].n.size) for row in rng.integers(
            0, s[0].n.size, size=(rounds, s[0].n.size))]).astype(float)
        for s in per_trace
    ]  # fmt: skip
    totals: dict[str, dict[str, list[FloatArray]]] = {}
    logs_before: list[FloatArray] = []
    logs_after: list[FloatArray] = []
    for sums, w in zip(per_trace, weights, strict=True):
        for name, s in zip(("u", "F"), sums, strict=True):
            n, r, r2 = w @ s.n, w @ s.rec, w @ s.rec2
            eb, ea = w @ s.err_before, w @ s.err_after
            parts = totals.setdefault(name, {k: [] for k in ("n", "r", "r2", "eb", "ea")})
            for key, v in (("n", n), ("r", r), ("r2", r2), ("eb", eb), ("ea", ea)):
                parts[key].append(v)
            n_safe = np.maximum(n, 1.0)
            logs_before.append(np.log(np.maximum(np.sqrt(eb / n_safe) / s.scale, 1e-300)))
            logs_after.append(np.log(np.maximum(np.sqrt(ea / n_safe) / s.scale, 1e-300)))
    tail = 50 * (1 - level)
    pct = (tail, 100 - tail)
    channel: dict[str, Intervals] = {"before": {}, "after": {}}
    for name, parts in totals.items():
        n, r, r2 = (np.sum(parts[k], axis=0) for k in ("n", "r", "r2"))
        spread = np.sqrt(np.maximum(r2 - r**2 / np.maximum(n, 1.0), 1e-300))
        for when, key in (("before", "eb"), ("after", "ea")):
            nrmse = np.sqrt(np.sum(parts[key], axis=0)) / spread
            lo, hi = np.percentile(nrmse, pct)
            channel[when][name] = (float(lo), float(hi))
    x_before = np.exp(np.mean(logs_before, axis=0))
    x_after = np.exp(np.mean(logs_after, axis=0))
    closure = np.maximum(-1.0, (x_before - x_after) / np.maximum(x_before - 1.0, 1e-12))
    lo, hi = np.percentile(closure, pct)
    return channel, (float(lo), float(hi))
