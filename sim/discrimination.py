"""How far apart two rival models are, measured as the diagnosis will measure them.

The diagnosis never runs a model open loop over a whole recording: it cuts each
recording into segments after every slack episode and restarts each segment from the
*measured* state (multiple shooting, ``sim.identify.shooting``), so chaos after a snatch
is cut off after one segment and what it compares is each candidate's short-term
dynamics. A plan must predict the separation on those terms, or it promises what the
diagnosis will not see (open loop, two nearly equal models part ways after the first
snatch) and misses what it will (a force channel's delay against a gauge low-pass
differs most in the snatches themselves).

So, for a motion and two rivals A and B: A's open-loop run stands in for the recording
(A is the truth), it is cut into segments exactly as a recording would be
(``Trace.segments``), and A and B both run from its measured states on those segments,
B at its values and one step off each parameter a re-diagnosis refits (the baseline's
stiffness, damping and friction scales, B's own effect parameters). What remains of
A − B beyond those directions (least squares), RMS in noise units, is how far B misses
if A is true; the pair's separation is the lesser of the two ways round, since either
may be the truth.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from sim.effects.registry import EFFECTS, EffectSpec
from sim.identify.traces import Trace, make_trace
from sim.model import Model, Variant
from sim.params import StandParams

__all__ = [
    "BASELINE_STEPS",
    "baseline_steps",
    "effect_steps",
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
    if directions.size:
        coef, *_ = np.linalg.lstsq(directions, difference, rcond=None)
        difference = difference - directions @ coef
    return float(np.sqrt(2.0 * np.mean(np.square(difference))))


def recording_of(
    name: str, x_m: FloatArray, u_m: FloatArray, force_n: FloatArray, rate_hz: float, mass: float
) -> Trace:
    """A run as the diagnosis sees a recording (its drive filtered, u from rest, cut)."""
    t = np.arange(x_m.size) / rate_hz
    return make_trace(name, t, x_m, u_m, force_n, mass)


def _lead_samples(effects: Sequence[EffectSpec], rate_hz: float) -> int:
    """How many samples ahead a channel is recorded (a negative skew), +1; 0 if none."""
    early = 0.0
    for spec in effects:
        values = spec.resolved()
        for param in EFFECTS[spec.name].leads:
            early = max(early, -values[param])
    return int(np.ceil(early * rate_hz)) + 1 if early > 0 else 0


def shooting_separation(
    recording: Trace,
    stand: StandParams,
    truth: Sequence[EffectSpec],
    model: Sequence[EffectSpec],
    noise_u_m: float,
    noise_force_n: float,
) -> float:
    """How far ``model`` misses ``truth`` on a recording's segments, after a refit.

    Both run from the recording's measured states (``truth``'s open-loop run, say) on
    its segments, so what the restarts themselves miss (the state estimate, smoothed
    over a snatch: 3.6 noise units of a model against its own noise-free recording of a
    light weight's quick rectangle) is common to both and cancels, as it does between
    two candidates in the diagnosis. ``stand`` (at the recording's mass): the baseline
    at its fitted values; ``truth``, ``model``: the effects on top of it. Noise units:
    ``noise_u_m`` and ``noise_force_n`` (rms).
    """
    seg = recording.segments
    rate = recording.rate_hz

    def runs(effects: Sequence[EffectSpec], variants: list[Variant]) -> FloatArray:
        restarts = seg.restarts_ahead(_lead_samples(effects, rate))
        u, f = Model(stand, effects).run_segments(recording.x_m, rate, restarts, variants)
        return np.concatenate([seg.assemble(u) / noise_u_m, seg.assemble(f) / noise_force_n], 1)

    target = runs(truth, [{}])[0]
    z = runs(model, [{}, *baseline_steps(stand), *effect_steps(model)])
    return residual_separation(target - z[0], np.asarray((z[1:] - z[0]).T, dtype=np.float64))
