"""The paper's tested situations as presets (STAND.md §4; paper Table 1, Figs. 5–13).

The paper names each situation's signal shape, its rate class and the weight, but gives
no amplitudes or timings. Those below are our assumptions [estimate], chosen with the
baseline model (``final`` parameters, default drive limits) so that:

* the quick situations (f > 1 Hz) slacken the fibre briefly with the 8.131 kg weight —
  the snatches the paper reports — while the weight's excursion stays within about 1.5×
  the drive stroke (nobody ran a test that throws the weight up its guide);
* the slow ones (f < 1 Hz) keep the fibre taut throughout: with the final stiffness the
  weight mode is only ≈ 9 Hz and lightly damped, so a ramp faster than ≈ 0.08 m/s would
  already ring it slack at the corners.

Situations 3 and 4 use the drive motions of 11 and 12a with the light weight, as in the
paper. ``tests/test_situations.py`` pins the slack/taut and excursion properties.
"""

from __future__ import annotations

from dataclasses import dataclass

from drivers.signals import Shape, SignalSpec

__all__ = ["SITUATIONS", "Situation", "situation"]

LIGHT_KG = 3.096
HEAVY_KG = 8.131


@dataclass(frozen=True)
class Situation:
    """A named paper situation: the drive signal and the weight."""

    name: str
    signal: SignalSpec
    mass_kg: float
    rate_class: str  # "quicker" (f > 1 Hz) or "slower" (f < 1 Hz), the paper's words
    note: str


_QUICK_11 = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=5, ramp_fraction=0.4)
_SLOW_12A = SignalSpec(Shape.TRAPEZOIDAL, 0.040, 0.25, cycles=3, ramp_fraction=0.25)

SITUATIONS: dict[str, Situation] = {
    s.name: s
    for s in (
        Situation("3", _QUICK_11, LIGHT_KG, "quicker", "drive motion of 11, light weight"),
        Situation("4", _SLOW_12A, LIGHT_KG, "slower", "drive motion of 12a, light weight"),
        Situation(
            "10",
            SignalSpec(Shape.TRAPEZOIDAL, 0.025, 1.25, cycles=4, ramp_fraction=0.4),
            HEAVY_KG,
            "quicker",
            "the paper's 'not a typical quicker situation': milder than 11",
        ),
        Situation("11", _QUICK_11, HEAVY_KG, "quicker", "2 Hz, the paper's quickest"),
        Situation("12a", _SLOW_12A, HEAVY_KG, "slower", "slow trapezoid"),
        Situation(
            "14",
            SignalSpec(Shape.QUASI_SINUSOIDAL, 0.060, 0.5, cycles=3),
            HEAVY_KG,
            "slower",
            "raised cosine",
        ),
    )
}


def situation(name: str) -> Situation:
    """Look a situation up by its paper name ('3', '4', '10', '11', '12a', '14')."""
    try:
        return SITUATIONS[name]
    except KeyError:
        known = ", ".join(SITUATIONS)
        raise KeyError(f"no paper situation {name!r}; known: {known}") from None
