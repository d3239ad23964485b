"""The next test: the admissible motion whose outcome best tells rival models apart.

A *rival* is one explanation of a stand's gap as a model: the fitted baseline plus its
effects at their fitted parameters. For each motion of a coarse grid (shapes, strokes,
rates, ramps, weights), the safety prediction (``sim.prediction``, worst over the
parameters' range and over the rivals, ``PLAN_MARGIN`` below every limit, little slack)
decides whether it may run; on those that may, each rival runs open loop from rest, at
its values and a step off each of its parameters. The *separation* of two rivals is the
RMS difference of their recorded channels over the motion, in units of the gauges' noise
(u and F together), after projecting off what a re-diagnosis would refit: the baseline's
stiffness, damping and friction and both rivals' own parameters. The plan is the
admissible motion with the largest separation of its worst-separated pair.

Motions run in batches padded to one length (rest at the end), so the prediction's
corners and each rival are one batch per chunk of motions, on all cores.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from drivers.limits import DriveLimits, LimitError
from drivers.signals import Shape, SignalSpec, plan_motion
from sim.effects.registry import EFFECTS, EffectSpec
from sim.envelope import (
    MotionFigures,
    Prediction,
    SlackRule,
    Spread,
    StandEnvelope,
    figures_of,
    worst_of,
)
from sim.model import BatchResult, Model
from sim.params import StandParams
from sim.prediction import corner_variants

__all__ = [
    "PLAN_MARGIN",
    "PREDICTABLE_SLACK",
    "Candidate",
    "Noise",
    "Plan",
    "Rival",
    "Setting",
    "motion_grid",
    "param_steps",
    "search",
    "separation",
]

FloatArray = NDArray[np.float64]
Clock = Callable[[], float]

#: The grid [estimate]: strokes, rates and ramps spanning the drive's range coarsely.
AMPLITUDES_MM = (10.0, 25.0, 45.0, 70.0, 90.0)
FREQUENCIES_HZ = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0)
RAMP_FRACTIONS = (0.1, 0.25, 0.4)
#: Each motion lasts about this long (cycles = rate × this, at least 2), s: long enough
#: for the weight's response to settle into its cycle, short enough to keep the search
#: cheap; the separation is an RMS, so more cycles would not raise it.
MOTION_S = 3.0
DWELL_START_S, DWELL_END_S = 0.5, 1.0
#: The largest share of slack time a planned motion may have in the worst case: with
#: the fibre slack the weight flies, and open-loop runs of two nearly equal models part
#: ways (the paper: "can even have the character of chaos"); what separates them there
#: is the chaos, not the effect.
PREDICTABLE_SLACK = 0.05
#: How far below each limit a planned motion's worst case must stay, as a share of the
#: limit: the range of k, c and friction covers the baseline's uncertainty, not effects
#: the model lacks (on the other truth stand a pulley seat that jumps carried the weight
#: of a 90 mm, 1 Hz trapezoid 1 % beyond the travel the prediction allowed).
PLAN_MARGIN = 0.1
#: Motions per batch.
CHUNK = 24


@dataclass(frozen=True)
class Rival:
    """One explanation as a model: the effects on top of the (fitted) baseline."""

    name: str
    effects: tuple[EffectSpec, ...]


@dataclass(frozen=True)
class Noise:
    """The gauges' noise, the unit of separation: u in m, F in N (rms)."""

    u_m: float
    force_n: float


@dataclass(frozen=True)
class Candidate:
    """A motion the search considers."""

    spec: SignalSpec
    mass_kg: float

    def describe(self) -> str:
        """'a 4 Hz trapezoid of 25 mm with 8.131 kg' and the like."""
        kind = {
            Shape.RECTANGULAR: "rectangle",
            Shape.TRAPEZOIDAL: "trapezoid",
            Shape.QUASI_SINUSOIDAL: "quasi-sine",
        }[self.spec.shape]
        return (
            f"a {self.spec.frequency_hz:g} Hz {kind} of {self.spec.amplitude_m * 1e3:g} mm "
            f"with {self.mass_kg:g} kg"
        )


@dataclass(frozen=True)
class Plan:
    """The search's answer.

    Attributes
    ----------
    best
        The chosen motion, or None when no motion of the grid is admissible.
    separations
        Each rival pair's separation over the chosen motion, noise units.
    prediction
        The chosen motion's safety prediction (worst over the range and the rivals).
    searched, admissible
        Motions simulated, and those the prediction admits.
    complete
        False when the time budget ended the search early.
    """

    best: Candidate | None
    separations: dict[tuple[str, str], float]
    prediction: Prediction | None
    searched: int
    admissible: int
    complete: bool

    @property
    def expected_separation(self) -> float:
        """The worst-separated pair's separation, noise units."""
        return min(self.separations.values(), default=0.0)


def motion_grid(limits: DriveLimits, masses_kg: Sequence[float]) -> list[Candidate]:
    """Every grid motion the drive can make, in a fixed scattered order.

    The order is a seeded permutation, so that a search cut short by its budget has
    still seen the whole range coarsely.
    """
    grid = []
    for shape, a_mm, f_hz, mass in itertools.product(
        Shape, AMPLITUDES_MM, FREQUENCIES_HZ, masses_kg
    ):
        ramps = RAMP_FRACTIONS if shape is Shape.TRAPEZOIDAL else (0.25,)
        for ramp in ramps:
            cycles = max(2, round(MOTION_S * f_hz))
            spec = SignalSpec(shape, a_mm / 1e3, f_hz, cycles, ramp, DWELL_START_S, DWELL_END_S)
            try:
                plan_motion(spec, limits)
            except LimitError:
                continue
            grid.append(Candidate(spec, mass))
    order = np.random.default_rng(0).permutation(len(grid))
    return [grid[i] for i in order]


def _padded(
    candidates: Sequence[Candidate], limits: DriveLimits, rate_hz: float
) -> tuple[FloatArray, list[int]]:
    """The motions' drive positions padded with rest to one length, and their lengths."""
    xs = [plan_motion(c.spec, limits).sample(rate_hz)[1] for c in candidates]
    n = max(x.size for x in xs)
    out = np.zeros((len(xs), n))
    for row, x in zip(out, xs, strict=True):
        row[: x.size] = x
    return out, [x.size for x in xs]


@dataclass(frozen=True)
class Setting:
    """What the search needs besides the grid.

    Attributes
    ----------
    nominal
        The stand file's stand (any mass: each motion's mass replaces it).
    spread
        The plausible range of stiffness, damping and friction factors; its centre is the
        model's (a diagnosis' fitted scales).
    named
        The effects of the model the safety prediction uses (the diagnosis' named ones).
    rivals
        The explanations to separate; ``pairs`` names which against which.
    noise, envelope, rule, limits, rate_hz
        The separation's unit, the limits, the drive, the sample rate.
    """

    nominal: StandParams  # at no particular mass
    spread: Spread
    named: tuple[EffectSpec, ...]
    rivals: tuple[Rival, ...]
    pairs: tuple[tuple[str, str], ...]
    noise: Noise
    envelope: StandEnvelope
    rule: SlackRule
    limits: DriveLimits
    rate_hz: float


def _predictions(
    setting: Setting, mass: float, x: FloatArray, lengths: list[int]
) -> tuple[list[Prediction], BatchResult]:
    """The safety prediction of each motion (rows of x) over the spread's corners.

    Also the runs themselves: motion i's corners are rows i·9 … i·9 + 8, centre first.
    """
    stand = setting.nominal.with_(mass_kg=mass)
    corners = corner_variants(stand, setting.spread)
    rows = np.repeat(x, len(corners), axis=0)
    res = Model(stand, setting.named).run_batch(rows, setting.rate_hz, corners * len(x))
    out = []
    for i, n in enumerate(lengths):
        figs = [
            figures_of(
                res.true_force_n[j, :n],
                res.force_n[j, :n],
                res.true_u_m[j, :n],
                setting.rate_hz,
                setting.rule.slack_force_n,
            )
            for j in range(i * len(corners), (i + 1) * len(corners))
        ]
        out.append(Prediction(figs[0], worst_of(figs), len(figs)))
    return out, res


def _scaled(u: FloatArray, f: FloatArray, noise: Noise) -> FloatArray:
    """u and F stacked in noise units."""
    return np.concatenate([u / noise.u_m, f / noise.force_n], axis=-1)


def _nuisance(res: BatchResult, i: int, n: int, noise: Noise, corners: int) -> FloatArray:
    """Motion i's output directions of the baseline's parameters: corners − centre, (2n, 8)."""
    rows = slice(i * corners, (i + 1) * corners)
    z = _scaled(res.u_m[rows, :n], res.force_n[rows, :n], noise)
    return np.asarray((z[1:] - z[0]).T, dtype=np.float64)


def separation(difference: FloatArray, nuisance: FloatArray) -> float:
    """RMS of a difference of two runs (stacked u, F in noise units) beyond the nuisance.

    The part a refit of the baseline's stiffness, damping and friction would absorb (the
    least-squares projection on the corners' directions) does not count.
    """
    coef, *_ = np.linalg.lstsq(nuisance, difference, rcond=None)
    rest = difference - nuisance @ coef
    return float(np.sqrt(2.0 * np.mean(np.square(rest))))


def param_steps(rival: Rival) -> list[dict[str, float]]:
    """A small step of each of the rival's fitted effect parameters (a refit moves them)."""
    steps = []
    for spec in rival.effects:
        values = spec.resolved()
        for p in EFFECTS[spec.name].params:
            if not p.fit or p.integer:
                continue
            v = values[p.name]
            step = 0.05 * abs(v) if abs(v) > 1e-3 * (p.high - p.low) else 0.02 * (p.high - p.low)
            steps.append({f"{spec.name}.{p.name}": v + step if v + step <= p.maximum else v - step})
    return steps


@dataclass(frozen=True)
class _RivalRuns:
    """A rival's runs: per motion its centre, then one per parameter step (``sets`` rows)."""

    res: BatchResult
    sets: int

    def channels(self, j: int, n: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Motion j's recorded u, F and true u, F at the centre."""
        r, row = self.res, j * self.sets
        return r.u_m[row, :n], r.force_n[row, :n], r.true_u_m[row, :n], r.true_force_n[row, :n]

    def directions(self, j: int, n: int, noise: Noise) -> FloatArray:
        """Motion j's output directions of the rival's own parameters, (2n, steps)."""
        rows = slice(j * self.sets, (j + 1) * self.sets)
        z = _scaled(self.res.u_m[rows, :n], self.res.force_n[rows, :n], noise)
        return np.asarray((z[1:] - z[0]).T, dtype=np.float64)


def _rival_runs(setting: Setting, mass: float, x: FloatArray) -> dict[str, _RivalRuns]:
    """Each rival on every motion (rows of x): at its values, and a step off each."""
    stand = setting.nominal.with_(mass_kg=mass)
    centre = corner_variants(stand, setting.spread)[0]
    runs = {}
    for rival in setting.rivals:
        variants = [centre] + [{**centre, **step} for step in param_steps(rival)]
        rows = np.repeat(x, len(variants), axis=0)
        res = Model(stand, rival.effects).run_batch(rows, setting.rate_hz, variants * len(x))
        runs[rival.name] = _RivalRuns(res, len(variants))
    return runs


def _rival_figures(
    runs: dict[str, _RivalRuns], j: int, n: int, setting: Setting
) -> list[MotionFigures]:
    figures = []
    for r in runs.values():
        _, f, true_u, true_f = r.channels(j, n)
        figures.append(figures_of(true_f, f, true_u, setting.rate_hz, setting.rule.slack_force_n))
    return figures


def search(
    setting: Setting, grid: Sequence[Candidate], budget_s: float, clock: Clock = time.monotonic
) -> Plan:
    """Search the grid (in its order) until done or the budget is spent."""
    started = clock()
    best: tuple[float, Candidate, dict[tuple[str, str], float], Prediction] | None = None
    searched = admissible = 0
    complete = True
    for k in range(0, len(grid), CHUNK):
        if k and clock() - started > budget_s:  # the first chunk always runs
            complete = False
            break
        chunk = grid[k : k + CHUNK]
        for mass in sorted({c.mass_kg for c in chunk}):
            group = [c for c in chunk if c.mass_kg == mass]
            searched += len(group)
            for found in _judge(setting, mass, group):
                admissible += 1
                if best is None or found[0] > best[0]:
                    best = found
    if best is None:
        return Plan(None, {}, None, searched, admissible, complete)
    return Plan(best[1], best[2], best[3], searched, admissible, complete)


def _judge(
    setting: Setting, mass: float, group: Sequence[Candidate]
) -> list[tuple[float, Candidate, dict[tuple[str, str], float], Prediction]]:
    """The group's admissible motions: (score, motion, separations, prediction) each."""
    x, lengths = _padded(group, setting.limits, setting.rate_hz)
    predictions, corners = _predictions(setting, mass, x, lengths)
    ok = [i for i, p in enumerate(predictions) if _admissible(p, setting)]
    if not ok:
        return []
    runs = _rival_runs(setting, mass, x[ok])
    found = []
    for j, i in enumerate(ok):
        n, pred = lengths[i], predictions[i]
        rivals = _rival_figures(runs, j, n, setting)
        pred = Prediction(pred.nominal, worst_of([pred.worst, *rivals]), pred.runs + len(rivals))
        if not _admissible(pred, setting):
            continue
        baseline = _nuisance(corners, i, n, setting.noise, predictions[i].runs)
        scaled = {name: _scaled(*r.channels(j, n)[:2], setting.noise) for name, r in runs.items()}
        seps = {}
        for a, b in setting.pairs:
            own = [runs[a].directions(j, n, setting.noise), runs[b].directions(j, n, setting.noise)]
            seps[(a, b)] = separation(scaled[a] - scaled[b], np.hstack([baseline, *own]))
        found.append((min(seps.values()), group[i], seps, pred))
    return found


def _admissible(prediction: Prediction, setting: Setting) -> bool:
    """Within ``PLAN_MARGIN`` of the limits, and predictable open loop (little slack)."""
    margins = prediction.margins(setting.envelope, setting.rule)
    if min(margins.values()) < PLAN_MARGIN:
        return False
    return prediction.worst.slack_share <= PREDICTABLE_SLACK
