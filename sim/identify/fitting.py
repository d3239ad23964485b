"""Bounded, reproducible least-squares fits of the model (with or without an effect).

A *candidate* is the baseline model plus at most one effect. Its free parameters are the
baseline's uncertain ones — fibre stiffness, fibre damping and the friction table's scale,
as multipliers of the nominal stand (log scale for the first two) — and the effect's
fitted parameters within their plausible ranges (sim.effects.registry). Why these three:
the paper tuned exactly them; mass, geometry and g are measured, not uncertain.

The objective is output error: per trace and channel (u, F), the sum of squared
residuals normalised by the recorded channel's spread, i.e. the sum of NRMSE², on the
training samples (every ``stride``-th). Jacobians are forward differences computed as one
parallel batch of simulations. Output-error landscapes are rugged across slack and snatch
events, so every fit starts from several points and keeps the best; starts are fixed, so
fits are reproducible.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from functools import partial

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from sim.effects import EFFECTS
from sim.identify.candidates import BASELINE_PARAMS, Candidate, FitResult, FreeParam
from sim.identify.heldout import Outputs
from sim.identify.least_cost import TraceCost, least_cost_point
from sim.identify.side_by_side import in_lanes, side_by_side
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
log = logging.getLogger(__name__)
#: What a fit fits lives in ``candidates``; named here too, where the fits are.
__all__ = [
    "BASELINE_PARAMS", "Candidate", "FitResult", "FreeParam", "Objective", "effect_grid_start",
    "fit", "grid_axis", "least_cost_values", "scan_thresholds", "simulate_values",
]  # fmt: skip


def _early_s(values: dict[str, float]) -> float:
    """How far ahead of its time a channel is recorded (``EffectInfo.leads``), s; 0 if none."""
    leads = {f"{info.name}.{p}" for info in EFFECTS.values() for p in info.leads}
    return max([0.0] + [-v for k, v in values.items() if k in leads])


def simulate_values(
    candidate: Candidate,
    values: Sequence[dict[str, float]],
    trace: Trace,
    nominal: StandParams,
    shooting: bool = True,
    samples: IntArray | None = None,
    serial: bool = False,
) -> tuple[FloatArray, FloatArray]:
    """Recorded-channel outputs u (m), F (N) of a candidate for many value sets, in parallel.

    With ``shooting`` (always, in the diagnosis) each trace is simulated as segments
    restarted from measured states (``shooting``), assembled to full length; without, open
    loop from rest over the whole trace (chaotic for the light weight in quick motions).
    ``samples``: only the outputs at these samples (sets, len(samples)), simulating only
    the segments that hold them (all up to the last of them if the model carries states
    from segment to segment). ``serial``: the shooting runs on the calling thread
    (``side_by_side``).
    """
    model = candidate.model(nominal, trace.mass_kg)
    variants = [candidate.variant(nominal, v) for v in values]
    ahead = math.ceil(max((_early_s(v) for v in values), default=0.0) * trace.rate_hz)
    if not shooting:
        res = model.run_batch(trace.x_m, trace.rate_hz, variants)
        u, f = res.u_m, res.force_n
    elif samples is not None:
        seg = trace.segments
        if model.chained:  # as the whole trace's runs below
            restarts, position, offset = seg.leading(samples, ahead + 1 if ahead else 0)
        else:
            restarts, position, offset = seg.covering(samples, ahead + 1)
        u, f = model.run_segments(trace.x_m, trace.rate_hz, restarts, variants, serial)
        return u[:, position, offset], f[:, position, offset]
    else:
        seg = trace.segments
        restarts = seg.restarts_ahead(ahead + 1 if ahead else 0)
        u, f = model.run_segments(trace.x_m, trace.rate_hz, restarts, variants, serial)
        u, f = seg.assemble(u), seg.assemble(f)
    return (u, f) if samples is None else (u[:, samples], f[:, samples])


def scored_samples(trace: Trace, stride: int = 4) -> IntArray:
    """The training samples a fit (and the score test) compares: every ``stride``-th."""
    return np.flatnonzero(trace.present & trace.train)[::stride]


def channel_spread(recorded: FloatArray, samples: IntArray) -> float:
    """A channel's spread over the compared samples, its residuals' unit (1 if flat)."""
    return float(np.linalg.norm(recorded[samples] - recorded[samples].mean())) or 1.0


def weighed_by_miss(traces: Sequence[Trace], reference: Sequence[Outputs]) -> list[Trace]:
    """The traces with a fit's units set to the ``reference`` model's training miss.

    The held-out test pools each recording's channels as a geometric mean of their
    errors in noise units, so a channel counts by the share of its error a model removes.
    A fit in each channel's spread counts a precise dial gauge's u next to nothing once
    its error is a fraction of the stroke: on top of a dial gauge, a side load's refit
    halved F's held-out error and doubled u's (18.8 to 36.4 noise units), and a pulley's
    inertia that left u alone was named instead. Each channel's miss by the model the
    refit builds on as its unit is one Gauss–Newton step on that geometric mean: there
    the side load took u to 4.6 and F to 1.9, and was named.
    """
    weighed = []
    for tr, out in zip(traces, reference, strict=True):
        idx = np.flatnonzero(tr.present & tr.train)
        units = tuple(
            float(np.sqrt(np.mean((sim[idx] - rec[idx]) ** 2))) if idx.size else 0.0
            for sim, rec in ((out.u_m, tr.u_m), (out.force_n, tr.force_n))
        )
        weighed.append(tr.with_fit_units((units[0], units[1])))
    return weighed


def _units(trace: Trace, idx: IntArray) -> tuple[float, float]:
    """A trace's residual units over the scored samples ``idx`` (spread, or ``fit_units``)."""
    if trace.fit_units is None or not all(u > 0.0 for u in trace.fit_units):
        return channel_spread(trace.u_m, idx), channel_spread(trace.force_n, idx)
    scale = math.sqrt(max(idx.size, 1))
    return trace.fit_units[0] * scale, trace.fit_units[1] * scale


class Objective:
    """Residuals of a candidate over traces; simulations batched across parameter sets."""

    def __init__(
        self, candidate: Candidate, traces: Sequence[Trace], nominal: StandParams, stride: int = 4
    ) -> None:
        self.candidate = candidate
        self.traces = list(traces)
        self.nominal = nominal
        self.stride = stride
        self.simulations = 0
        self._cache: dict[bytes, FloatArray] = {}
        self._masks = []
        for tr in self.traces:
            idx = scored_samples(tr, stride)
            self._masks.append((idx, *_units(tr, idx)))
        # How far each trace's runs go: its last scored sample (what a run costs).
        self._spans = [int(idx[-1]) if idx.size else 0 for idx, _, _ in self._masks]

    @property
    def scored_span(self) -> int:
        """Samples the runs cover up to the last scored one, summed over the traces."""
        return sum(self._spans)

    def residuals_batch(self, zs: FloatArray) -> FloatArray:
        """Residual vectors for many parameter vectors at once, shape (sets, residuals).

        One parameter set runs the traces side by side (``side_by_side``).
        """
        values = [self.candidate.natural(z) for z in zs]
        self.simulations += len(zs) * len(self.traces)

        def trace_residuals(k: int, serial: bool) -> list[FloatArray]:
            tr, (idx, su, sf) = self.traces[k], self._masks[k]
            u, f = simulate_values(
                self.candidate, values, tr, self.nominal, samples=idx, serial=serial
            )
            return [(u - tr.u_m[idx]) / su, (f - tr.force_n[idx]) / sf]

        if len(zs) == 1:
            per_trace = side_by_side(trace_residuals, self._spans)
        else:
            per_trace = [trace_residuals(k, False) for k in range(len(self.traces))]
        out = np.concatenate([part for parts in per_trace for part in parts], axis=1)
        return np.where(np.isfinite(out), out, 1e3)  # a diverged run is simply very bad

    def residuals(self, z: FloatArray) -> FloatArray:
        """One residual vector (memoised: least_squares asks for it twice)."""
        key = np.asarray(z, dtype=np.float64).tobytes()
        if key not in self._cache:
            self._cache = {key: self.residuals_batch(np.atleast_2d(z))[0]}
        return self._cache[key]

    def jacobian(
        self,
        z: FloatArray,
        columns: NDArray[np.bool_] | None = None,
        steps: FloatArray | None = None,
    ) -> FloatArray:
        """Forward differences of the chosen columns (default: all), in one batch.

        ``steps``: each parameter's step (optimiser coordinates; default 1e-3 of its range).
        """
        lo = np.array([p.bounds()[0] for p in self.candidate.params])
        hi = np.array([p.bounds()[1] for p in self.candidate.params])
        step = 1e-3 * (hi - lo) if steps is None else steps
        which = np.flatnonzero(np.ones(z.size, bool) if columns is None else columns)
        # least_squares has just asked for the residuals at z: they are memoised.
        key = np.asarray(z, dtype=np.float64).tobytes()
        known = key in self._cache
        zs = [] if known else [z]
        signs = []
        for i in which:
            zi = z.copy()
            sign = 1.0 if z[i] + step[i] <= hi[i] else -1.0
            zi[i] += sign * step[i]
            zs.append(zi)
            signs.append(sign)
        r = self.residuals_batch(np.stack(zs))
        if known:
            r = np.concatenate([self._cache[key][None, :], r])
        self._cache = {key: r[0]}
        cols = [(r[k + 1] - r[0]) / (signs[k] * step[i]) for k, i in enumerate(which)]
        return np.stack(cols, axis=1)


#: Baseline pre-search grid (multipliers of nominal): slack and snatch timing make the
#: output error rugged in the stiffness, so a local fit from nominal alone can stall.
GRID_STIFFNESS = np.geomspace(0.6, 1.6, 9)
GRID_DAMPING = (0.5, 1.0, 2.0)
GRID_FRICTION = (0.5, 1.0, 1.5)
GRID_STARTS = 3


def _grid_starts(objective: Objective) -> list[FloatArray]:
    """The best few points of a coarse grid over the baseline multipliers (one batch)."""
    grid = np.array(
        [
            [np.log(k), np.log(c), f]
            for k in GRID_STIFFNESS
            for c in GRID_DAMPING
            for f in GRID_FRICTION
        ]
    )
    costs = np.sum(objective.residuals_batch(grid) ** 2, axis=1)
    return [grid[i] for i in np.argsort(costs)[:GRID_STARTS]]


#: Levels per parameter inside its typical range, by the effect's number of fitted
#: parameters (plus one level on each side out to the physical bounds: at most 4³ = 64
#: points, one batch).
EFFECT_GRID_LEVELS = {1: 8, 2: 5, 3: 2}


def grid_axis(p: FreeParam, levels: int) -> FloatArray:
    """Start-grid levels of one parameter (optimiser coordinates): dense where typical."""
    lo, hi = p.bounds()
    if p.integer:  # a count: its first level; the scan after the local fit finds the rest
        return np.array([p.to_internal(p.scan[0])])
    if p.held is not None:  # a form parameter: where it is held
        return np.array([p.to_internal(p.held)])
    if p.typical is None:
        return np.linspace(lo, hi, levels + 2)[1:-1]
    t_lo = float(np.clip(p.to_internal(max(p.typical[0], p.low)), lo, hi))
    t_hi = float(np.clip(p.to_internal(min(p.typical[1], p.high)), lo, hi))
    # One level where the typical range is a single value (a form's usual exponent).
    axis = list(np.linspace(t_lo, t_hi, levels + 2)[1:-1]) if t_hi > t_lo else [t_lo]
    edge = 1e-6 * (hi - lo)
    if t_lo - lo > edge:
        axis.append(0.5 * (lo + t_lo))
    if hi - t_hi > edge:
        axis.append(0.5 * (t_hi + hi))
    return np.sort(np.asarray(axis))


def effect_grid_start(
    candidate: Candidate,
    traces: Sequence[Trace],
    nominal: StandParams,
    baseline: dict[str, float],
    extra: Sequence[dict[str, float]] = (),
    stride: int = 4,
) -> dict[str, float]:
    """The best start for an effect's refit: a coarse grid over its own parameters.

    The baseline's parameters stay at their fit; the effect's take interior levels of
    their typical ranges (log-spaced where they span decades) and one level on each side
    between the typical range and the physical bound, all in one batch, with ``extra``
    (e.g. the screening's best probe) as further points. The effects' output error is
    rugged (a ringing span's damping ratio: a factor 2 off triples the cost), so a local
    fit needs a start in the right basin: spread evenly over the physical ranges, which
    are decades wider, the grid lost a light-weight Maxwell branch (τ 0.08 s; the grid's
    τ levels 0.08 s apart by a factor 3.5, the refit stuck at 0.29 s). The least-cost
    point is found by bounds (``least_cost``): the same point, fewer simulations.
    """
    points = effect_grid_points(candidate, baseline, extra)
    costs, sizes = trace_costs(candidate, traces, nominal, stride)
    recorded = range(len(points) - len(extra), len(points))
    return candidate.natural(points[least_cost_point(costs, sizes, points, recorded)])


def effect_grid_points(
    candidate: Candidate, baseline: dict[str, float], extra: Sequence[dict[str, float]] = ()
) -> FloatArray:
    """``effect_grid_start``'s points (optimiser coordinates), the ``extra`` ones last."""
    own = [p for p in candidate.params if p.name not in baseline]
    levels = EFFECT_GRID_LEVELS.get(len(own), 2)
    axes = [grid_axis(p, levels) for p in own]
    base = {p.name: p.to_internal(baseline[p.name]) for p in candidate.params if p.name in baseline}
    points = []
    for combo in np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(own)):
        z = dict(base)
        z.update({p.name: float(v) for p, v in zip(own, combo, strict=True)})
        points.append(np.array([z[p.name] for p in candidate.params]))
    points += [candidate.internal({**baseline, **values}) for values in extra]
    return np.stack(points)


def trace_costs(
    candidate: Candidate, traces: Sequence[Trace], nominal: StandParams, stride: int = 4
) -> tuple[list[TraceCost], list[int]]:
    """Each trace's training cost of many parameter vectors, and how far its runs go.

    A fit's residuals are per trace, so these sum to its cost (``least_cost`` prunes by
    them).
    """
    parts = [Objective(candidate, [tr], nominal, stride) for tr in traces]
    return [partial(_batch_cost, part) for part in parts], [part.scored_span for part in parts]


def _batch_cost(objective: Objective, zs: FloatArray) -> FloatArray:
    """Training cost of many parameter vectors (sets, params): shape (sets,)."""
    return np.asarray(np.sum(objective.residuals_batch(zs) ** 2, axis=1), dtype=np.float64)


def least_cost_values(
    candidate: Candidate,
    traces: Sequence[Trace],
    nominal: StandParams,
    points: Sequence[dict[str, float]],
    stride: int = 4,
) -> tuple[dict[str, float], float, int]:
    """The least training cost among whole value sets, in one batch: (values, cost, sims).

    Values outside a parameter's range are clipped into it, as a fit's start would be.
    """
    objective = Objective(candidate, traces, nominal, stride)
    zs = np.stack([candidate.internal(v) for v in points])
    costs = _batch_cost(objective, zs)
    best = int(np.argmin(costs))
    return candidate.natural(zs[best]), float(costs[best]), objective.simulations


def fit(
    candidate: Candidate,
    traces: Sequence[Trace],
    nominal: StandParams,
    baseline: dict[str, float] | None = None,
    stride: int = 4,
    max_nfev: int = 40,
    single_start: bool = False,
    ftol: float = 1e-8,
) -> FitResult:
    """Fit a candidate's free parameters on the traces' training samples (multi-start).

    ``single_start`` starts only from ``baseline`` (which then also holds the effect's
    values, e.g. the screening's best probe). ``ftol``: stop once an accepted step lowers
    the cost by less than this share of it (and the step went as the model predicted).
    """
    lo = np.array([p.bounds()[0] for p in candidate.params])
    hi = np.array([p.bounds()[1] for p in candidate.params])
    starts = candidate.start_points(baseline)
    grid_sims = 0
    if not candidate.effects and baseline is None:
        grid = Objective(candidate, traces, nominal, stride)
        starts = _grid_starts(grid)
        grid_sims = grid.simulations
    if single_start and baseline is not None:
        middle = {p.name: 0.5 * (p.low + p.high) for p in candidate.params if p.held is None}
        starts = [candidate.internal({**middle, **baseline})]
    # Thresholds (``FreeParam.scan``) stay where the start put them: a gradient cannot
    # move a parameter whose output error changes in steps. Held form parameters stay too.
    free = np.array([not p.scan and p.held is None for p in candidate.params])

    def local(k: int) -> tuple[float, FloatArray, int]:
        """The local fit from start k: (cost, values, simulations), on its own objective."""
        objective = Objective(candidate, traces, nominal, stride)
        z0 = np.clip(starts[k], lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))

        def full(zf: FloatArray) -> FloatArray:
            z = z0.copy()
            z[free] = zf
            return z

        sol = least_squares(
            lambda zf: objective.residuals(full(zf)), z0[free],
            jac=lambda zf: objective.jacobian(full(zf), free),
            bounds=(lo[free], hi[free]), method="trf", x_scale="jac", max_nfev=max_nfev,
            xtol=1e-6, ftol=ftol,
        )  # fmt: skip
        cost = float(np.sum(sol.fun**2))
        log.debug("%s start %s -> cost %.6g (%d evals)", candidate.name, z0, cost, sol.nfev)
        return cost, full(sol.x), objective.simulations

    # The starts side by side (``in_lanes``); the first of the least cost is kept.
    local_fits = in_lanes(local, [1.0] * len(starts))
    cost, best, _ = min(local_fits, key=lambda f: f[0])
    sims = grid_sims + sum(f[2] for f in local_fits)
    return FitResult(candidate, candidate.natural(best), cost, sims)


def scan_thresholds(
    candidate: Candidate,
    traces: Sequence[Trace],
    nominal: StandParams,
    values: dict[str, float],
    stride: int = 4,
) -> tuple[dict[str, float], float, int]:
    """Each threshold parameter scanned at the others' values: (values, cost, simulations).

    One batch over its levels, then one between the best level's neighbours (9 points; a
    count: its levels only): the cost is a step function of a threshold, flat between
    the recorded episodes it separates, so only a scan finds the step that matters.
    """
    objective = Objective(candidate, traces, nominal, stride)
    z = np.array([p.to_internal(values[p.name]) for p in candidate.params])
    cost = float(np.sum(objective.residuals(z) ** 2))
    for i, p in enumerate(candidate.params):
        if not p.scan:
            continue
        levels = np.array([p.to_internal(float(np.clip(v, p.low, p.high))) for v in p.scan])
        for _ in range(1 if p.integer else 2):
            zs = np.repeat(z[None, :], levels.size, axis=0)
            zs[:, i] = levels
            costs = np.sum(objective.residuals_batch(zs) ** 2, axis=1)
            j = int(np.argmin(costs))
            if costs[j] < cost:
                cost, z = float(costs[j]), zs[j].copy()
            lo_j, hi_j = levels[max(j - 1, 0)], levels[min(j + 1, levels.size - 1)]
            levels = np.linspace(lo_j, hi_j, 11)[1:-1]
    return candidate.natural(z), cost, objective.simulations
