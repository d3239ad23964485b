"""The next test: the admissible motion whose outcome best tells rival models apart.

A *rival* is one explanation of a stand's gap as a model: the fitted baseline plus its
effects at their fitted parameters. For each motion of a coarse grid (shapes, strokes,
rates, ramps, weights), the safety prediction (``sim.prediction``, worst over the
parameters' range and over the rivals, ``PLAN_MARGIN`` below every limit) decides
whether it may run; on those that may, each rival runs open loop from rest and stands in
for a recording. The *separation* of two rivals is how far one misses the other's
recording on the diagnosis' own multiple-shooting segments, after what a re-diagnosis
would refit (``sim.discrimination``), in units of the gauges' noise, the lesser way
round. The plan is the admissible motion that tells most pairs apart (by ``DECISIVE``
noise units); among those that tell every pair apart, the one that narrows the widest
interval most (``Narrowing``: the most information about that parameter beyond what a
refit absorbs, ``sim.discrimination.parameter_information``); else the one with the
largest separation of its worst-separated pair.

Motions run in batches padded to one length (rest at the end), so the prediction's
corners and each rival are one batch per chunk of motions, on all cores; the segment
runs are one batch per motion and rival.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from drivers.limits import DriveLimits
from sim.discrimination import parameter_information, recording_of, shooting_separation
from sim.effects.registry import EffectSpec
from sim.envelope import (
    MotionFigures,
    Prediction,
    SlackRule,
    Spread,
    StandEnvelope,
    figures_of,
    worst_of,
)
from sim.identify.traces import Trace
from sim.model import BatchResult, Model
from sim.motions import Candidate, lengthened, motion_grid, padded
from sim.params import StandParams
from sim.prediction import centre_stand, corner_variants

__all__ = [
    "DECISIVE",
    "PLAN_MARGIN",
    "Candidate",
    "Narrowing",
    "Noise",
    "Plan",
    "Rival",
    "Setting",
    "as_planned",
    "motion_grid",
    "plannable",
    "score",
    "search",
]

FloatArray = NDArray[np.float64]
Clock = Callable[[], float]

#: How far below each limit a planned motion's worst case must stay, as a share of the
#: limit: the range of k, c and friction covers the baseline's uncertainty, not effects
#: the model lacks (on the other truth stand a pulley seat that jumps carried the weight
#: of a 90 mm, 1 Hz trapezoid 1 % beyond the travel the prediction allowed).
PLAN_MARGIN = 0.1
#: Motions per batch.
CHUNK = 24
#: A separation of at least this many noise units tells a pair apart [estimate]: below
#: it the rivals' outputs differ by less than the gauges' noise, and a re-diagnosis may
#: well not settle it.
DECISIVE = 1.0


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
class Narrowing:
    """The interval a plan narrows second: a named effect's parameter and its 95 % interval.

    ``rival``: the rival whose model holds the parameter (the named effects'); ``held``:
    the information the recordings already hold about it (``parameter_information``
    summed over them), None where they are not at hand.
    """

    rival: str
    key: str
    value: float
    interval: tuple[float, float]
    held: float | None = None

    def predicted(self, information: float) -> tuple[float, float] | None:
        """The interval after a test that adds ``information``, if the recordings' is known.

        Information adds, so the interval's width shrinks by √(held / (held + added)).
        """
        if self.held is None or self.held <= 0.0:
            return None
        shrink = float(np.sqrt(self.held / (self.held + information)))
        low, high = self.interval
        return self.value - (self.value - low) * shrink, self.value + (high - self.value) * shrink


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
    options
        The admissible motions themselves (a side-by-side check draws among them).
    complete
        False when the time budget ended the search early.
    information
        What the chosen motion tells of the narrowed parameter (``Setting.narrow``).
    """

    best: Candidate | None
    separations: dict[tuple[str, str], float]
    prediction: Prediction | None
    searched: int
    admissible: int
    complete: bool
    options: tuple[Candidate, ...] = ()
    information: float = 0.0

    @property
    def expected_separation(self) -> float:
        """The worst-separated pair's separation, noise units."""
        return min(self.separations.values(), default=0.0)


def score(
    separations: dict[tuple[str, str], float], information: float = 0.0
) -> tuple[int, float, float]:
    """How well a motion settles: the pairs it tells apart, then the interval, then the worst.

    With several open questions (nothing named, each candidate against the baseline) a
    test that settles most of them beats one that settles none a little better; with
    one pair it is the separation itself. A motion that tells every pair apart has done
    the first job; among those, the one with the most ``information`` about the widest
    interval's parameter does the second.
    """
    told = sum(sep >= DECISIVE for sep in separations.values())
    second = information if told == len(separations) else 0.0
    return told, second, min(separations.values(), default=0.0)


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
    narrow
        The interval to narrow second, if any.
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
    narrow: Narrowing | None = None


def _predictions(
    setting: Setting, mass: float, x: FloatArray, lengths: list[int]
) -> list[Prediction]:
    """The safety prediction of each motion (rows of x) over the spread's corners."""
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
    return out


def _rival_runs(setting: Setting, mass: float, x: FloatArray) -> dict[str, BatchResult]:
    """Each rival open loop from rest on every motion (rows of x), at the model's centre."""
    stand = setting.nominal.with_(mass_kg=mass)
    centre = corner_variants(stand, setting.spread)[0]
    return {
        rival.name: Model(stand, rival.effects).run_batch(x, setting.rate_hz, [centre] * len(x))
        for rival in setting.rivals
    }


def _rival_figures(
    runs: dict[str, BatchResult], j: int, n: int, setting: Setting
) -> list[MotionFigures]:
    slack_n = setting.rule.slack_force_n
    return [
        figures_of(r.true_force_n[j, :n], r.force_n[j, :n], r.true_u_m[j, :n], rate, slack_n)
        for r, rate in ((r, setting.rate_hz) for r in runs.values())
    ]


def _recordings(
    setting: Setting, stand: StandParams, runs: dict[str, BatchResult], j: int, x: FloatArray
) -> dict[str, Trace]:
    """Each rival's run on motion j as the diagnosis would see its recording."""
    n = x.size
    noise = setting.noise
    return {
        name: recording_of(name, x, r.u_m[j, :n], r.force_n[j, :n], setting.rate_hz,
                           stand.mass_kg, (noise.u_m, noise.force_n))
        for name, r in runs.items()
    }  # fmt: skip


def _information(setting: Setting, stand: StandParams, recordings: dict[str, Trace]) -> float:
    """What the narrowed rival's recording of a motion tells of its parameter (0: no narrowing)."""
    narrow = setting.narrow
    if narrow is None or narrow.rival not in recordings:
        return 0.0
    effects = next(r.effects for r in setting.rivals if r.name == narrow.rival)
    return parameter_information(recordings[narrow.rival], stand, effects, narrow.key,
                                 setting.noise.u_m, setting.noise.force_n)  # fmt: skip


def _separations(
    setting: Setting, stand: StandParams, recordings: dict[str, Trace]
) -> dict[tuple[str, str], float]:
    """Each pair's separation on a motion, on the diagnosis' segments, the lesser way round."""
    noise = setting.noise
    models = {rival.name: rival.effects for rival in setting.rivals}
    misses: dict[tuple[str, str], float] = {}

    def miss(truth: str, model: str) -> float:
        if (truth, model) not in misses:
            misses[(truth, model)] = shooting_separation(
                recordings[truth], stand, models[truth], models[model], noise.u_m, noise.force_n
            ).against_floor
        return misses[(truth, model)]

    def nested(inner: str, outer: str) -> bool:
        return {e.name for e in models[inner]} < {e.name for e in models[outer]}

    # A model nested in its rival (the baseline in "an effect against none") is not
    # judged as the rival's miss of it: the rival's own parameters can switch its effect
    # off, and the diagnosis names an effect only on evidence of a gain over the smaller
    # model. So only the smaller model's miss of the larger one's recording counts.
    return {
        (a, b): miss(a, b) if nested(b, a) else miss(b, a) if nested(a, b)
        else min(miss(a, b), miss(b, a))
        for a, b in setting.pairs
    }  # fmt: skip


#: A judged motion: its score, itself, each pair's separation, its safety prediction, and
#: what it tells of the narrowed parameter.
_Judged = tuple[
    tuple[int, float, float], Candidate, dict[tuple[str, str], float], Prediction, float
]


def search(
    setting: Setting, grid: Sequence[Candidate], budget_s: float, clock: Clock = time.monotonic
) -> Plan:
    """Search the grid (in its order) until done or the budget is spent."""
    started = clock()
    best: _Judged | None = None
    searched = 0
    options: list[Candidate] = []
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
                options.append(found[1])
                if best is None or found[0] > best[0]:
                    best = found
    if best is None:
        return Plan(None, {}, None, searched, 0, complete)
    best = _as_planned(setting, best)
    return Plan(best[1], best[2], best[3], searched, len(options), complete, tuple(options),
                best[4])  # fmt: skip


def _as_planned(setting: Setting, found: _Judged) -> _Judged:
    """The motion lengthened to the planned test's length, if that too is admissible."""
    longer = lengthened(found[1], setting.limits)
    judged = _judge(setting, longer.mass_kg, [longer])
    return judged[0] if judged else found


def as_planned(setting: Setting, candidate: Candidate) -> Candidate:
    """A searched motion as a test is planned: lengthened (``lengthened``) if still admissible.

    The search judges short motions; the plan runs the chosen one longer, and a check that
    draws a motion among ``Plan.options`` runs it the same way.
    """
    longer = lengthened(candidate, setting.limits)
    return longer if _judge(setting, longer.mass_kg, [longer]) else candidate


def _judge(setting: Setting, mass: float, group: Sequence[Candidate]) -> list[_Judged]:
    """The group's admissible motions: (score, motion, separations, prediction) each."""
    x, lengths = padded(group, setting.limits, setting.rate_hz)
    predictions = _predictions(setting, mass, x, lengths)
    ok = [i for i, p in enumerate(predictions) if _admissible(p, setting)]
    if not ok:
        return []
    runs = _rival_runs(setting, mass, x[ok])
    fitted = centre_stand(setting.nominal.with_(mass_kg=mass), setting.spread)
    found = []
    for j, i in enumerate(ok):
        n, pred = lengths[i], predictions[i]
        rivals = _rival_figures(runs, j, n, setting)
        pred = Prediction(pred.nominal, worst_of([pred.worst, *rivals]), pred.runs + len(rivals))
        if not _admissible(pred, setting):
            continue
        recordings = _recordings(setting, fitted, runs, j, x[i, :n])
        seps = _separations(setting, fitted, recordings)
        information = _information(setting, fitted, recordings)
        found.append((score(seps, information), group[i], seps, pred, information))
    return found


def plannable(prediction: Prediction, envelope: StandEnvelope, rule: SlackRule) -> bool:
    """Whether the planner may choose a motion so predicted: ``PLAN_MARGIN`` inside every limit.

    Slack is allowed as far as the slack e-stop's limit (with the margin) allows: the
    diagnosis restarts its segments after every slack episode (``sim.discrimination``),
    so a snatch is no longer unpredictable chaos to it, and snatches are what excite a
    gauge's or a channel's high-frequency differences.
    """
    return min(prediction.margins(envelope, rule).values()) >= PLAN_MARGIN


def _admissible(prediction: Prediction, setting: Setting) -> bool:
    return plannable(prediction, setting.envelope, setting.rule)
