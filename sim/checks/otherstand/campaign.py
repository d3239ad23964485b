"""Campaigns of the other stand: a drawn "real" stand, its effects, four recordings.

The drive signals are not the ones the candidates were developed on (those are 25 mm
trapezoids at 2 and 1.25 Hz and a 60 mm quasi-sine): a small quick trapezoid, a
rectangle through a slower drive, a trapezoid that slackens the fibre, and a large slow
raised cosine, each with 0.5 s of rest before and after (``OTHER_FULL``, the
validation campaigns' set). A real lab runs other sets: a gentle one and a brisk one
(``OTHER_SETS``) check that the diagnosis does not hold only on the set it was tuned on.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from drivers.limits import DriveLimits
from drivers.signals import Shape, SignalSpec, plan_motion
from sim.checks.otherstand.gauges import Realism
from sim.checks.otherstand.outside import ALL_EFFECTS
from sim.checks.otherstand.stand import simulate
from sim.params import StandParams

FloatArray = NDArray[np.float64]

__all__ = [
    "OTHER_BRISK",
    "OTHER_FULL",
    "OTHER_GENTLE",
    "OTHER_SETS",
    "OTHER_SMALL",
    "OtherCampaign",
    "OtherRecording",
    "draw_true_stand",
    "make_other_campaign",
]


@dataclass(frozen=True)
class OtherRecording:
    """One recording's drive: a signal and the drive limits it runs under."""

    name: str
    signal: SignalSpec
    limits: DriveLimits = field(default_factory=DriveLimits)


_SLOW_DRIVE = DriveLimits(amplitude_max_m=0.090, speed_max_m_s=0.3, accel_max_m_s2=3.0)
_BRISK_DRIVE = DriveLimits(amplitude_max_m=0.090, speed_max_m_s=0.6, accel_max_m_s2=6.0)


def _spec(shape: Shape, a: float, f: float, cycles: int, ramp: float = 0.25) -> SignalSpec:
    return SignalSpec(shape, a, f, cycles=cycles, ramp_fraction=ramp, dwell_start_s=0.5,
                      dwell_end_s=0.5)  # fmt: skip


#: Four recordings, ~22 s: quick, rectangle, slack-making burst, slow.
OTHER_FULL = (
    OtherRecording("quick", _spec(Shape.TRAPEZOIDAL, 0.010, 2.0, 6)),
    OtherRecording("rect", _spec(Shape.RECTANGULAR, 0.040, 1.0, 4), _SLOW_DRIVE),
    OtherRecording("burst", _spec(Shape.TRAPEZOIDAL, 0.030, 1.0, 4, 0.2)),
    OtherRecording("slow", _spec(Shape.QUASI_SINUSOIDAL, 0.070, 0.4, 3)),
)
#: Two recordings, ~10 s, for quick checks: the burst and the slow one.
OTHER_SMALL = (
    OtherRecording("burst", _spec(Shape.TRAPEZOIDAL, 0.030, 1.0, 4, 0.2)),
    OtherRecording("slow", _spec(Shape.QUASI_SINUSOIDAL, 0.070, 0.4, 2)),
)
#: Three gentle recordings, ~22 s: small strokes, slow ramps, the fibre never slack with
#: either weight (a stand run to spare the fibre): the effects show less, and multiple
#: shooting has no slack episode to restart after.
OTHER_GENTLE = (
    OtherRecording("small", _spec(Shape.TRAPEZOIDAL, 0.005, 1.0, 5, 0.3)),
    OtherRecording("sine", _spec(Shape.QUASI_SINUSOIDAL, 0.030, 0.8, 5)),
    OtherRecording("long", _spec(Shape.QUASI_SINUSOIDAL, 0.050, 0.25, 2)),
)
#: Four brisk recordings, ~20 s: quicker and larger than the four above, a faster drive
#: for the rectangle; three of them slacken the fibre with either weight, for most of
#: their motion in the rectangle and the burst.
OTHER_BRISK = (
    OtherRecording("fast", _spec(Shape.TRAPEZOIDAL, 0.015, 3.0, 9, 0.3)),
    OtherRecording("rect", _spec(Shape.RECTANGULAR, 0.060, 1.5, 5), _BRISK_DRIVE),
    OtherRecording("burst", _spec(Shape.TRAPEZOIDAL, 0.040, 1.5, 5, 0.2)),
    OtherRecording("wide", _spec(Shape.QUASI_SINUSOIDAL, 0.085, 0.5, 3)),
)
#: The recording sets by name (``diagnose-check --truth other --recordings NAME``).
OTHER_SETS = {
    "moderate": OTHER_FULL,
    "gentle": OTHER_GENTLE,
    "brisk": OTHER_BRISK,
    "small": OTHER_SMALL,
}


def draw_true_stand(nominal: StandParams, rng: np.random.Generator) -> StandParams:
    """The true stand: k × 0.8–1.25, c × 0.7–1.4, friction × 0.8–1.25 (log-uniform)."""

    def factor(lo: float, hi: float) -> float:
        return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))

    return nominal.with_(
        stiffness_n_m=nominal.stiffness_n_m * factor(0.8, 1.25),
        damping_n_s_m=nominal.damping_n_s_m * factor(0.7, 1.4),
        friction_scale=nominal.friction_scale * factor(0.8, 1.25),
    )


@dataclass(frozen=True)
class OtherCampaign:
    """What a campaign gives: recordings (as measured), the noise-free truth, the answer.

    ``recordings``: (name, t, x, u, F) per recording, as a recorder writes them (x and u
    absolute, u with the dial gauge's offset). ``truth_u``/``truth_f``: the recorded
    channels without noise, u counted from its rest reading. ``effects``: the true
    effects and parameters; ``stand``: the true stand.
    """

    recordings: list[tuple[str, FloatArray, FloatArray, FloatArray, FloatArray]]
    truth_u: list[FloatArray]
    truth_f: list[FloatArray]
    effects: dict[str, dict[str, float]]
    stand: StandParams


def make_other_campaign(
    nominal: StandParams,
    effects: Sequence[str],
    rng: np.random.Generator,
    recordings: Sequence[OtherRecording] = OTHER_FULL,
    rate_hz: float = 2000.0,
    realism: Realism | None = None,
    params: Mapping[str, Mapping[str, float]] | None = None,
) -> OtherCampaign:
    """Draw a true stand and the named effects' parameters; record the campaign.

    ``params`` fixes parameters instead of drawing them (for tests).
    """
    stand = draw_true_stand(nominal, rng)
    chosen: dict[str, dict[str, float]] = {}
    for name in effects:
        given = (params or {}).get(name)
        chosen[name] = dict(given) if given is not None else ALL_EFFECTS[name].draw(rng)
    noise = realism or Realism()
    out: list[tuple[str, FloatArray, FloatArray, FloatArray, FloatArray]] = []
    truth_u, truth_f = [], []
    for rec in recordings:
        t, x = plan_motion(rec.signal, rec.limits).sample(rate_hz)
        run = simulate(stand, chosen, x, rate_hz)
        x_rec, u_rec, f_rec = noise.apply(x, run.u_m, run.force_n, rate_hz, rng)
        out.append((rec.name, t, x_rec, u_rec, f_rec))
        rest = max(int(0.4 * rate_hz), 1)
        truth_u.append(run.u_m - float(np.mean(run.u_m[:rest])))
        truth_f.append(run.force_n)
    return OtherCampaign(out, truth_u, truth_f, chosen, stand)
