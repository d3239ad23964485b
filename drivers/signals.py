"""Drive signals: the rectangular, trapezoidal and quasi-sinusoidal motions of the stand.

The real drive and the simulation consume the same motion, so it is planned here, once.

Each signal has an ideal *reference* shape (STAND.md §3) and a *motion*: what the drive
actually executes within its speed and acceleration limits.

* rectangular: the reference steps 0 → A → 0; the drive turns each step into a
  time-optimal move (accelerate at a_max, cruise at v_max, brake at a_max).
* trapezoidal: ramps of constant speed A/t_ramp and holds; the reference's velocity steps
  at each corner, which the drive rounds off at a_max.
* quasi-sinusoidal: the raised cosine A·(1 − cos 2πft)/2 per cycle, continuous in position
  and velocity; executed as it is, so it must lie within the limits itself.

Rounding a corner at constant acceleration is a moving average of the reference over
τ = Δv/a_max (a box filter): it keeps the move centred on the ideal corner and never
exceeds the limits. A rectangular step filtered by two boxes (A/v_max, then v_max/a_max)
is exactly the time-optimal point-to-point move. Both are evaluated in closed form from
antiderivatives of the piecewise-polynomial reference, so sampling is exact.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from drivers.limits import (
    CYCLES_MAX,
    DWELL_MAX_S,
    FREQUENCY_MIN_HZ,
    PROFILE_CLOCK_MAX_S,
    DriveLimits,
    InvalidSignalError,
    LimitError,
)

if TYPE_CHECKING:
    from scipy.interpolate import PPoly

FloatArray = NDArray[np.float64]

__all__ = [
    "DriveProfile",
    "Shape",
    "SignalSpec",
    "check_duration",
    "check_values",
    "plan_motion",
]


class Shape(StrEnum):
    """The drive signal shapes of the stand."""

    RECTANGULAR = "rectangular"
    TRAPEZOIDAL = "trapezoidal"
    QUASI_SINUSOIDAL = "quasi-sinusoidal"


@dataclass(frozen=True)
class SignalSpec:
    """What the operator asks for.

    Attributes
    ----------
    shape
        Signal shape.
    amplitude_m
        Stroke A, m (0 < A ≤ the drive's amplitude limit).
    frequency_hz
        Cycle rate f, Hz; the period is 1/f.
    cycles
        Number of cycles.
    ramp_fraction
        Trapezoidal only: rise (and fall) time as a fraction of the period, (0, 0.5].
    dwell_start_s
        Rest at x = 0 before the motion starts, s.
    dwell_end_s
        Rest at x = 0 after the motion ends, s (to watch the weight settle).
    """

    shape: Shape
    amplitude_m: float
    frequency_hz: float
    cycles: int = 1
    ramp_fraction: float = 0.25
    dwell_start_s: float = 0.5
    dwell_end_s: float = 1.0

    @property
    def period_s(self) -> float:
        """One cycle, s."""
        return 1.0 / self.frequency_hz

    def to_dict(self) -> dict[str, float | int | str]:
        """Plain values for metadata (units in the keys)."""
        return {
            "shape": str(self.shape),
            "amplitude_mm": self.amplitude_m * 1e3,
            "frequency_hz": self.frequency_hz,
            "cycles": self.cycles,
            "ramp_fraction": self.ramp_fraction,
            "dwell_start_s": self.dwell_start_s,
            "dwell_end_s": self.dwell_end_s,
        }


@dataclass(frozen=True)
class DriveProfile:
    """A planned drive motion that lies within the limits; x is downward positive, m."""

    spec: SignalSpec
    limits: DriveLimits
    duration_s: float
    motion_start_s: float
    peak_speed_m_s: float
    peak_accel_m_s2: float
    _reference: PPoly | None = field(repr=False, default=None)
    _box_widths_s: tuple[float, ...] = field(repr=False, default=())

    def reference_m(self, t_s: FloatArray) -> FloatArray:
        """The ideal signal shape at times t_s."""
        t = np.asarray(t_s, dtype=np.float64)
        if self._reference is None:
            return self._raised_cosine(t, 0)
        return np.asarray(self._reference(t), dtype=np.float64)

    def position_m(self, t_s: FloatArray) -> FloatArray:
        """Drive position the drive executes at times t_s, m."""
        return self._filtered(np.asarray(t_s, dtype=np.float64), 0)

    def velocity_m_s(self, t_s: FloatArray) -> FloatArray:
        """Drive velocity, m/s."""
        return self._filtered(np.asarray(t_s, dtype=np.float64), 1)

    def accel_m_s2(self, t_s: FloatArray) -> FloatArray:
        """Drive acceleration, m/s² (one-sided where it steps)."""
        return self._filtered(np.asarray(t_s, dtype=np.float64), 2)

    def sample(self, rate_hz: float) -> tuple[FloatArray, FloatArray]:
        """Times (i/rate, computed not accumulated) and positions over the whole run."""
        n = round(self.duration_s * rate_hz) + 1
        t = np.arange(n, dtype=np.float64) / rate_hz
        return t, self.position_m(t)

    def _raised_cosine(self, t: FloatArray, derivative: int) -> FloatArray:
        spec = self.spec
        w = 2 * math.pi * spec.frequency_hz
        phase = w * (t - self.motion_start_s)
        active = (t >= self.motion_start_s) & (
            t <= self.motion_start_s + spec.cycles / spec.frequency_hz
        )
        half_a = spec.amplitude_m / 2
        value = {
            0: half_a * (1 - np.cos(phase)),
            1: half_a * w * np.sin(phase),
            2: half_a * w * w * np.cos(phase),
        }[derivative]
        return np.where(active, value, 0.0)

    def _filtered(self, t: FloatArray, derivative: int) -> FloatArray:
        if self._reference is None:
            return self._raised_cosine(t, derivative)
        widths = self._box_widths_s
        order = len(widths) - derivative
        # The k-fold box filter of x_ref is a signed sum of its k-th antiderivative at
        # shifted times, divided by the product of the widths (see module docstring).
        base = self._reference.antiderivative(order) if order > 0 else self._reference
        if order < 0:
            base = self._reference.derivative(-order)
        total = np.zeros_like(t)
        for signs in itertools.product((1.0, -1.0), repeat=len(widths)):
            shift = sum(s * w / 2 for s, w in zip(signs, widths, strict=True))
            total += math.prod(signs) * base(t + shift)
        return total / math.prod(widths)


def check_values(spec: SignalSpec) -> None:
    """Raise InvalidSignalError for a value that describes no motion (NaN, ≤ 0, ...)."""
    if not (math.isfinite(spec.amplitude_m) and spec.amplitude_m > 0):
        raise InvalidSignalError(f"amplitude must be > 0 mm, got {spec.amplitude_m * 1e3:g} mm")
    if not (math.isfinite(spec.frequency_hz) and spec.frequency_hz > 0):
        raise InvalidSignalError(f"frequency must be > 0 Hz, got {spec.frequency_hz:g} Hz")
    if spec.cycles < 1:
        raise InvalidSignalError(f"cycles must be ≥ 1, got {spec.cycles}")
    for name in ("dwell_start_s", "dwell_end_s"):
        value = getattr(spec, name)
        if not (math.isfinite(value) and value >= 0):
            raise InvalidSignalError(f"{name} must be a finite number of s ≥ 0, got {value:g}")
    if spec.shape is Shape.TRAPEZOIDAL and not 0 < spec.ramp_fraction <= 0.5:
        raise InvalidSignalError(f"ramp fraction must lie in (0, 0.5], got {spec.ramp_fraction:g}")


def check_duration(spec: SignalSpec) -> None:
    """Refuse (LimitError) what the drive's profile parameters and clock cannot hold.

    Checked before planning: the planners loop over the cycles (10⁹ cycles never ended).
    """
    if spec.frequency_hz < FREQUENCY_MIN_HZ:
        raise LimitError(
            f"frequency {spec.frequency_hz:g} Hz is below the drive's {FREQUENCY_MIN_HZ:g} Hz "
            "(Pr 20.23 holds µHz)"
        )
    if spec.cycles > CYCLES_MAX:
        raise LimitError(f"{spec.cycles} cycles exceed the drive program's {CYCLES_MAX}")
    for name in ("dwell_start_s", "dwell_end_s"):
        if getattr(spec, name) > DWELL_MAX_S:
            raise LimitError(
                f"{name} {getattr(spec, name):g} s exceeds the drive's {DWELL_MAX_S:.0f} s "
                "(a 32-bit parameter of µs)"
            )
    total_s = spec.dwell_start_s + spec.cycles / spec.frequency_hz + spec.dwell_end_s
    if total_s >= PROFILE_CLOCK_MAX_S:
        raise LimitError(
            f"the motion lasts {total_s:.6g} s ({total_s / 3600:.3g} h); the drive's profile "
            f"clock (Pr 20.34) wraps at {PROFILE_CLOCK_MAX_S:.0f} s (5.96 h)"
        )


def _check_spec(spec: SignalSpec, limits: DriveLimits) -> None:
    check_values(spec)
    limits.check_amplitude(spec.amplitude_m)
    check_duration(spec)


def _levels_ppoly(breaks: list[float], coeffs: list[tuple[float, float]]) -> PPoly:
    """Piecewise-linear PPoly; coeffs are (slope, value at the left break) per interval."""
    from scipy.interpolate import PPoly  # scipy costs 0.3 s: not for `labstand CMD --help`

    c = np.array([[s for s, _ in coeffs], [v for _, v in coeffs]], dtype=np.float64)
    return PPoly(c, np.asarray(breaks, dtype=np.float64), extrapolate=True)


def _rectangular(spec: SignalSpec, limits: DriveLimits) -> DriveProfile:
    a, period = spec.amplitude_m, spec.period_s
    cruise = a / limits.speed_max_m_s
    ramp = limits.speed_max_m_s / limits.accel_max_m_s2
    if cruise < ramp:  # short move: the drive never reaches full speed (triangular speed)
        cruise = ramp = math.sqrt(a / limits.accel_max_m_s2)
    move_s = cruise + ramp
    if move_s > period / 2 * (1 + 1e-9):
        raise LimitError(
            f"the drive needs {move_s * 1e3:.0f} ms to move {a * 1e3:g} mm within its speed "
            f"and acceleration limits, but a half period at {spec.frequency_hz:g} Hz is "
            f"{period / 2 * 1e3:.0f} ms"
        )
    start = spec.dwell_start_s + move_s / 2  # the filtered move starts at dwell_start
    breaks = [start - 1e3]
    coeffs: list[tuple[float, float]] = [(0.0, 0.0)]
    for j in range(spec.cycles):
        c = start + j * period
        breaks += [c, c + period / 2]
        coeffs += [(0.0, a), (0.0, 0.0)]
    breaks.append(start + spec.cycles * period + 1e3)
    ref = _levels_ppoly(breaks, coeffs)
    duration = spec.dwell_start_s + spec.cycles * period + spec.dwell_end_s
    return DriveProfile(
        spec,
        limits,
        duration,
        spec.dwell_start_s,
        a / cruise,
        a / cruise / ramp,
        ref,
        (cruise, ramp),
    )


def _trapezoidal(spec: SignalSpec, limits: DriveLimits) -> DriveProfile:
    a, period = spec.amplitude_m, spec.period_s
    ramp_s = spec.ramp_fraction * period
    hold_s = period / 2 - ramp_s
    speed = a / ramp_s
    limits.check_speed(speed, "ramp speed")
    corner_dv = speed if hold_s > 0 else 2 * speed
    blend_s = corner_dv / limits.accel_max_m_s2
    shortest = min(ramp_s, hold_s) if hold_s > 0 else ramp_s
    if blend_s > shortest * (1 + 1e-9):
        raise LimitError(
            f"the drive needs {blend_s * 1e3:.0f} ms to change speed by {corner_dv:.3g} m/s at "
            f"{limits.accel_max_m_s2:g} m/s², longer than the {shortest * 1e3:.0f} ms ramp or "
            "hold: lower the frequency or the amplitude"
        )
    start = spec.dwell_start_s + blend_s / 2
    breaks = [start - 1e3]
    coeffs: list[tuple[float, float]] = [(0.0, 0.0)]
    for j in range(spec.cycles):
        c = start + j * period
        breaks += [c, c + ramp_s]
        coeffs += [(speed, 0.0), (0.0, a)]
        if hold_s > 0:
            breaks.append(c + period / 2)
            coeffs.append((-speed, a))
            breaks.append(c + period / 2 + ramp_s)
            coeffs.append((0.0, 0.0))
        else:
            breaks.append(c + period / 2)
            coeffs.append((-speed, a))
    breaks.append(start + spec.cycles * period + 1e3)
    coeffs_final = coeffs
    # Consecutive zero holds at the end merge harmlessly; PPoly needs len(breaks) = n + 1.
    ref = _levels_ppoly(breaks, coeffs_final)
    duration = spec.dwell_start_s + spec.cycles * period + spec.dwell_end_s
    accel = corner_dv / blend_s
    return DriveProfile(spec, limits, duration, spec.dwell_start_s, speed, accel, ref, (blend_s,))


def _quasi_sinusoidal(spec: SignalSpec, limits: DriveLimits) -> DriveProfile:
    w = 2 * math.pi * spec.frequency_hz
    speed = spec.amplitude_m / 2 * w
    accel = spec.amplitude_m / 2 * w * w
    limits.check_speed(speed)
    limits.check_accel(accel)
    duration = spec.dwell_start_s + spec.cycles * spec.period_s + spec.dwell_end_s
    return DriveProfile(spec, limits, duration, spec.dwell_start_s, speed, accel)


_PLANNERS = {
    Shape.RECTANGULAR: _rectangular,
    Shape.TRAPEZOIDAL: _trapezoidal,
    Shape.QUASI_SINUSOIDAL: _quasi_sinusoidal,
}


def plan_motion(spec: SignalSpec, limits: DriveLimits) -> DriveProfile:
    """Plan the drive motion for a signal, or refuse it with the limit it breaks.

    Raises
    ------
    LimitError
        The amplitude, speed, acceleration or timing lies beyond the drive's limits.
    """
    _check_spec(spec, limits)
    return _PLANNERS[spec.shape](spec, limits)
