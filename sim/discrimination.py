"""How far apart two rival models are, measured as the diagnosis will measure them.

The diagnosis never runs a model open loop over a whole recording: it cuts each
recording into segments after every slack episode and restarts each segment from the
*measured* state (multiple shooting, ``sim.identify.shooting``), so chaos after a snatch
is cut off after one segment and what it compares is each candidate's short-term
dynamics. A plan must predict the separation on those terms, or it promises what the
diagnosis will not see (open loop, two nearly equal models part ways after the first
snatch) and misses what it will (a force channel's delay against a gauge low-pass
differs most in the snatches themselves).

So, for a motion and two rivals A and B: A's open-loop run with the gauges' noise stands
in for the recording (A is the truth) and is cut into segments exactly as a recording
is (``Trace.segments``); A and B both run from its measured states on those segments, B
at its values and one step off each parameter a re-diagnosis refits (the baseline's
stiffness, damping and friction scales, B's own effect parameters). What remains of
A − B beyond those directions (least squares) is how far B misses if A is true; per
channel on the held-out cycles it counts against what A itself misses there, the noise
plus the restarts' own error (``Miss.against_floor``). The pair's separation is the
lesser of the two ways round, since either may be the truth (``sim.planner``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.effects.registry import EFFECTS, EffectSpec
from sim.identify.traces import Trace, make_trace
from sim.model import Model, Variant
from sim.params import StandParams

__all__ = [
    "BASELINE_STEPS",
    "Miss",
    "baseline_steps",
    "effect_steps",
    "parameter_information",
    "recording_of",
    "residual_separation",
    "shooting_separation",
]

FloatArray = NDArray[np.float64]

#: Relative steps of the baseline's refitted factors (stiffness, damping, friction): a
#: refit moves them, so the output directions they span do not separate rivals. Small
#: enough to stay linear, large enough to stand above the integrator's round-off.
BASELINE_STEPS = {"stiffness_n_m": 0.05, "damping_n_s_m": 0.1, "friction_scale": 0.1}


def baseline_steps(stand: StandParams) -> list[Variant]:
    """A step of each of the baseline's refitted factors off ``stand``."""
    return [{name: getattr(stand, name) * (1.0 + rel)} for name, rel in BASELINE_STEPS.items()]


def effect_steps(effects: Sequence[EffectSpec]) -> list[Variant]:
    """A small step of each fitted effect parameter (5 % of it, or 2 % of its range at 0)."""
    steps: list[Variant] = []
    for spec in effects:
        values = spec.resolved()
        for p in EFFECTS[spec.name].params:
            if not p.fit or p.integer:
                continue
            v = values[p.name]
            span = p.high - p.low
            step = 0.05 * abs(v) if abs(v) > 1e-3 * span else 0.02 * span
            steps.append({f"{spec.name}.{p.name}": v + step if v + step <= p.maximum else v - step})
    return steps


def residual_separation(difference: FloatArray, directions: FloatArray) -> float:
    """RMS of ``difference`` (u then F, noise units) beyond the span of ``directions``.

    ``directions`` (2n, m): what a refit would absorb, removed by least squares. The
    result is the RMS per channel pair: √2 × the RMS over the 2n stacked values.
    """
    beyond = _beyond(difference, directions.T)
    return float(np.sqrt(2.0 * np.mean(np.square(beyond))))


#: The gauges' noise added to a rival's run before it stands in for a recording is drawn
#: from this seed: the same for every motion, so a search is repeatable.
NOISE_SEED = 29


def recording_of(
    name: str,
    x_m: FloatArray,
    u_m: FloatArray,
    force_n: FloatArray,
    rate_hz: float,
    mass: float,
    noise: tuple[float, float] = (0.0, 0.0),
) -> Trace:
    """A run as the diagnosis sees a recording (its drive filtered, u from rest, cut).

    ``noise``: the gauges' rms noise (u in m, F in N) added first (``NOISE_SEED``): the
    diagnosis restarts its segments from states estimated on noisy channels, and on a
    noise-free run both the segment boundaries and the restart errors are unlike a
    recording's (a light weight's quick rectangle: a model's own miss of 127 noise units
    noise-free, 14 with noise).
    """
    rng = np.random.default_rng(NOISE_SEED)
    u = u_m + rng.normal(0.0, noise[0], u_m.size) if noise[0] > 0 else u_m
    f = force_n + rng.normal(0.0, noise[1], force_n.size) if noise[1] > 0 else force_n
    t = np.arange(x_m.size) / rate_hz
    return make_trace(name, t, x_m, u, f, mass)


def _lead_samples(effects: Sequence[EffectSpec], rate_hz: float) -> int:
    """How many samples ahead a channel is recorded (a negative skew), +1; 0 if none."""
    early = 0.0
    for spec in effects:
        values = spec.resolved()
        for param in EFFECTS[spec.name].leads:
            early = max(early, -values[param])
    return int(np.ceil(early * rate_hz)) + 1 if early > 0 else 0


@dataclass(frozen=True)
class Miss:
    """How far a model misses a recording on its segments, and the floor it is seen against.

    ``beyond_refit``: the model's miss of the truth's segment runs after a refit, noise
    units, u and F together (``residual_separation``). Per channel (u, F) on the
    recording's held-out cycles: ``channel_miss``, the same miss, and ``channel_floor``,
    the truth's own miss of the recording, rms in noise units: the noise plus what the
    restarts miss (states estimated from noisy channels, over a snatch), 1 for noise
    alone.
    """

    beyond_refit: float
    channel_miss: tuple[float, float]
    channel_floor: tuple[float, float]

    @property
    def against_floor(self) -> float:
        """The separation the diagnosis sees: √(∏ (1 + missᶜ²/floorᶜ²) − 1) over channels c.

        In units of the floor (noise units where no restart misses).

        The diagnosis pools its held-out error X over recordings and channels as a
        geometric mean of each one's rms in noise units (``heldout_excess``), so a test
        adds to the log of X, per channel, log √(1 + miss²/floor²) for the wrong model
        against the right one; this figure is monotone in their sum, and is miss/floor
        where one channel differs (1: the wrong model's error √2 times the right one's).
        """
        product = 1.0
        for miss, floor in zip(self.channel_miss, self.channel_floor, strict=True):
            product *= 1.0 + (miss / max(floor, 1.0)) ** 2
        return float(np.sqrt(product - 1.0))


def _segment_runs(
    recording: Trace,
    stand: StandParams,
    effects: Sequence[EffectSpec],
    variants: list[Variant],
    noise_u_m: float,
    noise_force_n: float,
) -> FloatArray:
    """A model's variants run from the recording's measured states on its segments.

    Rows: the variants; each u then F over the whole recording, in noise units.
    """
    seg = recording.segments
    rate = recording.rate_hz
    restarts = seg.restarts_ahead(_lead_samples(effects, rate))
    u, f = Model(stand, effects).run_segments(recording.x_m, rate, restarts, variants)
    return np.concatenate([seg.assemble(u) / noise_u_m, seg.assemble(f) / noise_force_n], 1)


def _beyond(difference: FloatArray, steps: FloatArray) -> FloatArray:
    """``difference`` less what the rows of ``steps`` span (a refit), by least squares."""
    if not steps.size:
        return difference
    columns = np.asarray(steps.T, dtype=np.float64)
    beyond: FloatArray = difference - columns @ np.linalg.lstsq(columns, difference, rcond=None)[0]
    return beyond


def _channel_rms(stacked: FloatArray, n: int, samples: NDArray[np.bool_]) -> tuple[float, float]:
    """RMS of u and of F (stacked: u's n values, then F's) over the selected samples."""
    rms = [float(np.sqrt(np.mean(stacked[c * n : (c + 1) * n][samples] ** 2))) for c in (0, 1)]
    return rms[0], rms[1]


def _recorded(recording: Trace, noise_u_m: float, noise_force_n: float) -> FloatArray:
    """The recording's u then F, in noise units."""
    return np.concatenate([recording.u_m / noise_u_m, recording.force_n / noise_force_n])


def shooting_separation(
    recording: Trace,
    stand: StandParams,
    truth: Sequence[EffectSpec],
    model: Sequence[EffectSpec],
    noise_u_m: float,
    noise_force_n: float,
) -> Miss:
    """How far ``model`` misses ``truth`` on a recording's segments, after a refit.

    Both run from the recording's measured states (``truth``'s run with the gauges'
    noise, say) on its segments, so what the restarts themselves miss is common to both
    and cancels in the difference, as it does between two candidates in the diagnosis;
    it stays in the floor (``Miss``). ``stand`` (at the recording's mass): the baseline
    at its fitted values; ``truth``, ``model``: the effects on top of it. Noise units:
    ``noise_u_m`` and ``noise_force_n`` (rms).
    """
    noise = (noise_u_m, noise_force_n)
    target = _segment_runs(recording, stand, truth, [{}], *noise)[0]
    variants = [{}, *baseline_steps(stand), *effect_steps(model)]
    z = _segment_runs(recording, stand, model, variants, *noise)
    miss = _beyond(target - z[0], z[1:] - z[0])
    n = recording.samples
    judged = recording.test if recording.test.any() else recording.present
    channel_miss = _channel_rms(miss, n, judged)
    channel_floor = _channel_rms(_recorded(recording, *noise) - target, n, judged)
    beyond = float(np.sqrt(2.0 * np.mean(miss**2)))
    return Miss(beyond, channel_miss, channel_floor)


def parameter_information(
    recording: Trace,
    stand: StandParams,
    effects: Sequence[EffectSpec],
    key: str,
    noise_u_m: float,
    noise_force_n: float,
) -> float:
    """What a recording tells of one effect parameter, beyond what a refit absorbs.

    The model runs from the recording's measured states on its segments (as
    ``shooting_separation``) at its values and one step off each parameter a re-diagnosis
    refits; the outputs' slope along ``key`` (``"effect.param"``), less what the other
    directions span (least squares), is summed in squares over the recording's samples
    in units of each channel's floor (the noise plus the restarts' own miss): Fisher's
    information about the parameter, per unit of it squared, as if the samples were
    independent. They are not, so the figure ranks motions and compares recordings of one
    stand (the share a test adds to what the recordings hold), not an interval by itself.
    """
    steps = effect_steps(effects)
    own = next((s for s in steps if key in s), None)
    if own is None:
        raise ValueError(f"{key} is not a fitted parameter of {[e.name for e in effects]}")
    effect, name = key.split(".", 1)
    value = next(spec for spec in effects if spec.name == effect).resolved()[name]
    others = [s for s in steps if key not in s]
    variants = [{}, own, *baseline_steps(stand), *others]
    z = _segment_runs(recording, stand, effects, variants, noise_u_m, noise_force_n)
    slope = _beyond((z[1] - z[0]) / (own[key] - value), z[2:] - z[0])
    off = _recorded(recording, noise_u_m, noise_force_n) - z[0]
    n = recording.samples
    information = 0.0
    for c in (0, 1):
        part = slice(c * n, (c + 1) * n)
        ok = recording.present & np.isfinite(off[part]) & np.isfinite(slope[part])
        floor = float(np.sqrt(np.mean(off[part][ok] ** 2)))
        information += float(np.sum(slope[part][ok] ** 2)) / max(floor, 1.0) ** 2
    return information
