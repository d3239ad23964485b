"""Drive signals: shapes, continuity, limits, refusals."""

from __future__ import annotations

import re

import numpy as np
import pytest

from drivers.limits import DriveLimits, InvalidSignalError, LimitError
from drivers.signals import Shape, SignalSpec, plan_motion

LIMITS = DriveLimits()
RATE = 20_000.0  # fine sampling so jumps stand out against smooth changes


def _motion(shape: Shape, amplitude_m: float = 0.05, frequency_hz: float = 1.0, **kw: float):
    profile = plan_motion(SignalSpec(shape, amplitude_m, frequency_hz, cycles=2, **kw), LIMITS)
    t = np.arange(round(profile.duration_s * RATE) + 1) / RATE
    return profile, t


@pytest.mark.parametrize("shape", list(Shape))
def test_every_motion_starts_and_ends_at_rest_and_respects_the_limits(shape: Shape) -> None:
    profile, t = _motion(shape)
    x, v, a = profile.position_m(t), profile.velocity_m_s(t), profile.accel_m_s2(t)
    assert x[0] == pytest.approx(0, abs=1e-12) and x[-1] == pytest.approx(0, abs=1e-12)
    assert v[0] == pytest.approx(0, abs=1e-12) and v[-1] == pytest.approx(0, abs=1e-12)
    assert x.max() == pytest.approx(0.05, rel=1e-9)
    assert x.min() >= -1e-12
    assert np.abs(v).max() <= LIMITS.speed_max_m_s * (1 + 1e-9)
    assert np.abs(a).max() <= LIMITS.accel_max_m_s2 * (1 + 1e-9)
    # The motion starts exactly when the dwell ends.
    assert np.all(x[t < profile.motion_start_s - 1e-9] == 0)


@pytest.mark.parametrize("shape", list(Shape))
def test_executed_motion_is_continuous_in_position_and_velocity(shape: Shape) -> None:
    profile, t = _motion(shape)
    x, v = profile.position_m(t), profile.velocity_m_s(t)
    dt = 1 / RATE
    # Largest sample-to-sample change bounded by the limits: no jumps anywhere.
    assert np.abs(np.diff(x)).max() <= LIMITS.speed_max_m_s * dt * 1.001
    assert np.abs(np.diff(v)).max() <= LIMITS.accel_max_m_s2 * dt * 1.001
    # Velocity is the derivative of position (the closed forms agree).
    assert np.allclose(np.gradient(x, dt), v, atol=LIMITS.accel_max_m_s2 * dt)


def test_reference_shapes_have_the_continuity_stand_md_gives_them() -> None:
    rect, t = _motion(Shape.RECTANGULAR)
    trap, _ = _motion(Shape.TRAPEZOIDAL)
    sine, _ = _motion(Shape.QUASI_SINUSOIDAL)
    dt = 1 / RATE
    # rectangular: the position itself jumps by A
    assert np.abs(np.diff(rect.reference_m(t))).max() == pytest.approx(0.05)
    # trapezoidal: continuous position, velocity steps by the ramp speed A/(r·T)
    xr = trap.reference_m(t)
    assert np.abs(np.diff(xr)).max() <= 0.2 * dt * 1.001
    ramp_speed = 0.05 / (0.25 * 1.0)
    assert np.abs(np.diff(np.diff(xr) / dt)).max() == pytest.approx(ramp_speed, rel=1e-6)
    # quasi-sinusoidal: raised cosine, velocity continuous (no step larger than a·dt)
    xs = sine.reference_m(t)
    vs = np.diff(xs) / dt
    peak_accel = 0.05 / 2 * (2 * np.pi) ** 2
    assert np.abs(np.diff(vs)).max() <= peak_accel * dt * 1.01
    assert np.allclose(sine.position_m(t), xs)


def test_rectangular_step_becomes_the_time_optimal_move() -> None:
    profile, t = _motion(Shape.RECTANGULAR, amplitude_m=0.05)
    # 50 mm at a_max = 10 m/s² never reaches 1 m/s: a triangular speed profile with
    # peak sqrt(A·a) and duration 2·sqrt(A/a).
    v = profile.velocity_m_s(t)
    assert v.max() == pytest.approx(np.sqrt(0.05 * 10), rel=1e-3)
    moving = t[(np.abs(v) > 1e-9) & (t < profile.motion_start_s + 0.5)]
    assert moving[-1] - moving[0] == pytest.approx(2 * np.sqrt(0.05 / 10), abs=2 / RATE)


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (
            SignalSpec(Shape.TRAPEZOIDAL, 0.095, 0.5),
            "amplitude 95 mm exceeds the drive limit 90 mm",
        ),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.09, 5.0, ramp_fraction=0.1), "ramp speed 4.5 m/s exceeds"),
        (SignalSpec(Shape.QUASI_SINUSOIDAL, 0.09, 3.0), "peak acceleration 15.99 m/s²"),
        (SignalSpec(Shape.QUASI_SINUSOIDAL, 0.02, 16.0), "peak speed 1.005 m/s exceeds"),
        (SignalSpec(Shape.QUASI_SINUSOIDAL, 0.09, 2.5), "peak acceleration 11.1 m/s² exceeds"),
        (SignalSpec(Shape.RECTANGULAR, 0.09, 4.0), "the drive needs 190 ms to move 90 mm"),
        (
            SignalSpec(Shape.TRAPEZOIDAL, 0.06, 2.0, ramp_fraction=0.15),
            "needs 80 ms to change speed",
        ),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1e-9), "frequency 1e-09 Hz is below the drive's"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, cycles=10**9), "1000000000 cycles exceed"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, cycles=30_000), "profile clock (Pr 20.34) wraps"),
        (
            SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, dwell_end_s=1e9),
            "dwell_end_s 1e+09 s exceeds the drive's 2147 s",
        ),
        (
            SignalSpec(Shape.TRAPEZOIDAL, 0.05, 0.01, cycles=200, dwell_start_s=2000),
            "the motion lasts 22001 s",
        ),
    ],
)
def test_commands_beyond_the_limits_are_refused_with_the_limit(
    spec: SignalSpec, message: str
) -> None:
    with pytest.raises(LimitError, match=re.escape(message)):
        plan_motion(spec, LIMITS)


NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (SignalSpec(Shape.TRAPEZOIDAL, 0.0, 0.5), "amplitude must be > 0 mm"),
        (SignalSpec(Shape.TRAPEZOIDAL, -0.02, 0.5), "amplitude must be > 0 mm, got -20 mm"),
        (SignalSpec(Shape.TRAPEZOIDAL, NAN, 0.5), "amplitude must be > 0 mm, got nan mm"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, -1.0), "frequency must be > 0 Hz"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 0.0), "frequency must be > 0 Hz"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, INF), "frequency must be > 0 Hz, got inf"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, cycles=0), "cycles must be ≥ 1"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, ramp_fraction=0.7), "ramp fraction must lie in"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, dwell_start_s=NAN), "dwell_start_s must be a"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, dwell_end_s=INF), "dwell_end_s must be a"),
        (SignalSpec(Shape.TRAPEZOIDAL, 0.05, 1.0, dwell_end_s=-1), "dwell_end_s must be a"),
    ],
)
def test_values_that_describe_no_motion_are_bad_input_not_limits(
    spec: SignalSpec, message: str
) -> None:
    with pytest.raises(InvalidSignalError, match=re.escape(message)):
        plan_motion(spec, LIMITS)


def test_a_lower_configured_limit_refuses_what_the_default_allows() -> None:
    spec = SignalSpec(Shape.QUASI_SINUSOIDAL, 0.06, 1.0)
    plan_motion(spec, LIMITS)
    with pytest.raises(LimitError, match="peak speed"):
        plan_motion(spec, DriveLimits(speed_max_m_s=0.1))


def test_sampling_uses_computed_times() -> None:
    profile, _ = _motion(Shape.TRAPEZOIDAL)
    t, x = profile.sample(2000.0)
    assert np.array_equal(t, np.arange(t.shape[0]) / 2000.0)
    assert t[-1] == pytest.approx(profile.duration_s)
    assert np.array_equal(x, profile.position_m(t))
