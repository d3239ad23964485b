"""The simulated drive's motion: references and the position servo that follows them.

The servo is a PD position loop with velocity and acceleration feed-forward, stepped at a
fixed sub-sample rate (semi-implicit Euler), with the drive's hardware speed and
acceleration limits as saturations. The reference it sees is delayed by a small fixed
pipeline time, which is the tracking lag a test can expect:
x(t) ≈ r(t − delay) while the reference lies within the limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from drivers.limits import DriveLimits

FloatArray = NDArray[np.float64]

__all__ = ["Motion", "PointToPoint", "ServoSettings", "ServoState"]


class Motion(Protocol):
    """A planned motion in closed form (``drivers.signals.DriveProfile`` is one)."""

    @property
    def duration_s(self) -> float: ...  # noqa: D102
    def position_m(self, t_s: FloatArray) -> FloatArray: ...  # noqa: D102
    def velocity_m_s(self, t_s: FloatArray) -> FloatArray: ...  # noqa: D102
    def accel_m_s2(self, t_s: FloatArray) -> FloatArray: ...  # noqa: D102


@dataclass(frozen=True)
class ServoSettings:
    """How the simulated drive moves (all [estimate]).

    Attributes
    ----------
    reference_delay_s
        Pipeline delay between the profile and the position loop, s (the tracking lag).
    bandwidth_hz
        Position-loop natural frequency, Hz (critically damped).
    speed_margin, accel_margin
        The drive's hardware limits as multiples of the stand's configured limits.
    substeps
        Servo steps per gauge sample.
    over_travel_margin_m
        The drive trips when |x| exceeds the amplitude limit by more than this, m.
    watchdog_timeout_s
        Longest time between two 0 → 1 edges of control-word bit 14 once armed, s.
    home_tolerance_m
        A profile starts only within this distance of x = 0, m.
    lead_m_per_rev
        Linear travel per motor revolution, m (for rpm and encoder parameters).
    """

    reference_delay_s: float = 0.002
    bandwidth_hz: float = 40.0
    speed_margin: float = 1.2
    accel_margin: float = 1.5
    substeps: int = 4
    over_travel_margin_m: float = 0.002
    watchdog_timeout_s: float = 1.0
    home_tolerance_m: float = 0.0005
    lead_m_per_rev: float = 0.010


@dataclass
class ServoState:
    """Position loop state: drive position and velocity (m, m/s), downward positive."""

    x_m: float = 0.0
    v_m_s: float = 0.0

    def step(
        self,
        dt_s: float,
        ref: tuple[float, float, float],
        gains: tuple[float, float],
        v_max: float,
        a_max: float,
    ) -> None:
        """One servo step towards reference (r, ṙ, r̈)."""
        r, rd, rdd = ref
        kp, kd = gains
        a = rdd + kd * (rd - self.v_m_s) + kp * (r - self.x_m)
        a = min(max(a, -a_max), a_max)
        v = min(max(self.v_m_s + a * dt_s, -v_max), v_max)
        self.x_m += v * dt_s
        self.v_m_s = v

    def coast(self, dt_s: float, a_max: float) -> None:
        """Output disabled: the axis brakes to a stop at the hardware deceleration."""
        dv = min(abs(self.v_m_s), a_max * dt_s)
        self.v_m_s -= math.copysign(dv, self.v_m_s)
        self.x_m += self.v_m_s * dt_s


class PointToPoint:
    """Time-optimal move from x0 to x1 within speed and acceleration limits (home move)."""

    def __init__(self, x0_m: float, x1_m: float, limits: DriveLimits) -> None:
        self.x0, self.dist = x0_m, x1_m - x0_m
        d, v, a = abs(self.dist), limits.speed_max_m_s, limits.accel_max_m_s2
        self.t_acc = min(v / a, math.sqrt(d / a)) if d > 0 else 0.0
        self.v_peak = a * self.t_acc
        self.t_cruise = (d - a * self.t_acc**2) / self.v_peak if self.v_peak > 0 else 0.0
        self.accel = a
        self.duration_s = 2 * self.t_acc + self.t_cruise

    def _unsigned(self, t: FloatArray, derivative: int) -> FloatArray:
        a, ta, tc, vp = self.accel, self.t_acc, self.t_cruise, self.v_peak
        t = np.clip(np.asarray(t, dtype=np.float64), 0.0, self.duration_s)
        t2 = t - ta - tc  # time into the braking phase
        if derivative == 0:
            acc = 0.5 * a * np.minimum(t, ta) ** 2
            cruise = vp * np.clip(t - ta, 0.0, tc)
            brake = np.where(t2 > 0, vp * t2 - 0.5 * a * t2**2, 0.0)
            return acc + cruise + brake
        if derivative == 1:
            return np.where(t < ta, a * t, np.where(t2 > 0, vp - a * t2, vp))
        return np.where(t < ta, a, np.where(t2 > 0, -a, 0.0))

    def _signed(self, t_s: FloatArray, derivative: int) -> FloatArray:
        sign = 1.0 if self.dist >= 0 else -1.0
        value = sign * self._unsigned(t_s, derivative)
        inside = (np.asarray(t_s) >= 0) & (np.asarray(t_s) <= self.duration_s)
        if derivative == 0:
            return self.x0 + value
        return np.where(inside, value, 0.0)

    def position_m(self, t_s: FloatArray) -> FloatArray:
        """Position at t (from the start of the move), m."""
        return self._signed(t_s, 0)

    def velocity_m_s(self, t_s: FloatArray) -> FloatArray:
        """Velocity, m/s."""
        return self._signed(t_s, 1)

    def accel_m_s2(self, t_s: FloatArray) -> FloatArray:
        """Acceleration, m/s²."""
        return self._signed(t_s, 2)
