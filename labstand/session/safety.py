"""The run's emergency-stop rules, as pure checks on gauge blocks and drive polls.

Each check raises ``EStopError`` with a one-line reason naming the value, the limit and the
unit; the session then disables the drive at once. The rules (docs/acquisition.md):

* drive position x (gauges at 2 kHz, drive polls at 20 Hz) outside the planned range
  0 … A widened by ``position_margin_mm``;
* drive speed (polled) above the drive's speed limit by more than ``speed_margin``;
* the fibre slack (F < ``slack_force_n``) for longer than ``slack_max_s`` while the
  drive runs the profile: the weight is being flung (it once left its guide);
* a device that stops answering: no gauge data for ``gauge_timeout_s``; a Modbus
  time-out (the driver's own time-out and retries);
* the drive tripped, or its output went off while the profile should run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from drivers.interfaces import DriveState

__all__ = ["SAFETY_MAXIMA", "EStopError", "SafetyLimits", "SafetyMonitor"]


class EStopError(Exception):
    """A reason to stop the stand at once; ``str(err)`` is the one-line reason."""


#: The largest value of each threshold that keeps its rule meaningful [estimate]:
#: x may leave 0 … A by at most 10 mm (the 90 mm stroke ends 2 mm before the drive's
#: over-travel trip: a wider margin stops nothing the trip would not); the speed by at
#: most 50 %; the slack threshold stays below the light weight's 17 N rest tension; slack
#: may last at most 1 s (a weight falling 1 s has left its guide); the gauges may be
#: silent at most 1 s (50 frames: a slower rule let a silent stream end "Done", with
#: a third of the motion recorded).
SAFETY_MAXIMA = {
    "position_margin_mm": 10.0,
    "speed_margin": 0.5,
    "slack_force_n": 15.0,
    "slack_max_s": 1.0,
    "gauge_timeout_s": 1.0,
}


@dataclass(frozen=True)
class SafetyLimits:
    """Thresholds of the emergency stops (all [estimate], overridable per run).

    Attributes
    ----------
    position_margin_mm
        How far x may leave the planned range 0 … A, mm. The simulated servo follows
        within 0.1 mm; the drive's own over-travel trip sits 2 mm beyond its stroke.
    speed_margin
        Allowed excess of the polled drive speed over the drive's speed limit, as a
        fraction (0.1 = 10 %).
    slack_force_n
        Below this fibre force the fibre counts as slack, N (rest tension is 17 N with
        the light weight, 45 N with the heavy one; gauge noise ≈ 0.02 N).
    slack_max_s
        Longest slack episode tolerated while the drive runs, s. Quick paper-like runs
        (situation 11) go slack for ≈ 35 ms per cycle.
    gauge_timeout_s
        Longest silence of the gauge stream, s (data arrives every ≈ 20 ms).
    """

    position_margin_mm: float = 5.0
    speed_margin: float = 0.10
    slack_force_n: float = 2.0
    slack_max_s: float = 0.25
    gauge_timeout_s: float = 0.25

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"safety limit {name} must be > 0, got {value:g}")
            if value > SAFETY_MAXIMA[name]:
                raise ValueError(
                    f"safety limit {name} must be ≤ {SAFETY_MAXIMA[name]:g}, got {value:g} "
                    "(beyond it the rule would no longer stop the stand in time)"
                )

    def describe(self, x_range_mm: tuple[float, float], speed_max_m_s: float) -> str:
        """One line for the run's summary."""
        lo, hi = x_range_mm
        return (
            f"e-stop if x leaves {lo:g} … {hi:g} mm, speed > {speed_max_m_s:.3g} m/s, "
            f"slack (F < {self.slack_force_n:g} N) > {self.slack_max_s:g} s while running, "
            f"gauges silent > {self.gauge_timeout_s:g} s, a Modbus time-out or a trip"
        )


class SafetyMonitor:
    """Applies SafetyLimits to a run's data as it arrives.

    Parameters
    ----------
    limits
        The thresholds.
    amplitude_mm
        The planned stroke A, mm (x runs 0 … A).
    drive_speed_max_m_s
        The drive's speed limit, m/s.
    """

    def __init__(
        self, limits: SafetyLimits, amplitude_mm: float, drive_speed_max_m_s: float
    ) -> None:
        self.limits = limits
        margin = limits.position_margin_mm
        self.x_range_mm = (-margin, amplitude_mm + margin)
        self.speed_max_m_s = drive_speed_max_m_s * (1 + limits.speed_margin)
        self.running = False  # the drive runs the profile (slack matters only then)
        self._slack_since_us: int | None = None

    def describe(self) -> str:
        """The rules as one line."""
        return self.limits.describe(self.x_range_mm, self.speed_max_m_s)

    def widen_for(self, x_mm: float) -> None:
        """Let x start where it stands (a drive away from home moves back first)."""
        lo, hi = self.x_range_mm
        margin = self.limits.position_margin_mm
        self.x_range_mm = (min(lo, x_mm - margin), max(hi, x_mm + margin))

    def check_block(self, block: NDArray[np.void]) -> None:
        """Position envelope and slack on gauge samples (SAMPLE_DTYPE)."""
        x = block["x_mm"]
        lo, hi = self.x_range_mm
        outside = (x < lo) | (x > hi)
        if outside.any():
            value = float(x[int(np.argmax(outside))])
            raise EStopError(
                f"drive position x = {value:.2f} mm (gauges) outside the allowed {lo:g} … {hi:g} mm"
            )
        self._check_slack(block["force_n"] < self.limits.slack_force_n, block["t_device_us"])

    def _check_slack(self, slack: NDArray[np.bool_], t_us: NDArray[np.int64]) -> None:
        if not slack.any():
            self._slack_since_us = None
            return
        n = slack.size
        # start of the slack episode each sample belongs to: the sample after the last
        # taut one (or the episode carried over from the previous block)
        last_taut = np.maximum.accumulate(np.where(~slack, np.arange(n), -1))
        first = t_us[np.minimum(last_taut + 1, n - 1)]
        if self._slack_since_us is not None:
            first = np.where(last_taut < 0, self._slack_since_us, first)
        duration_us = np.where(slack, t_us - first, 0)
        self._slack_since_us = int(first[-1]) if slack[-1] else None
        longest_s = float(duration_us.max()) / 1e6
        if self.running and longest_s > self.limits.slack_max_s:
            raise EStopError(
                f"fibre slack (F < {self.limits.slack_force_n:g} N) for {longest_s:.2f} s "
                f"while the drive runs (limit {self.limits.slack_max_s:g} s): the weight "
                "may be flung"
            )

    def check_drive(self, state: DriveState, expect_active: bool) -> None:
        """Trip, output, position and speed of one drive poll."""
        if state.tripped:
            name = state.trip_name
            why = "" if name == f"trip {state.trip_code}" else f" ({name})"
            raise EStopError(f"the drive tripped: trip {state.trip_code}{why}")
        if expect_active and not state.active:
            raise EStopError("the drive's output went off by itself (not tripped)")
        x_mm = state.position_m * 1e3
        lo, hi = self.x_range_mm
        if not lo <= x_mm <= hi:
            raise EStopError(
                f"drive position x = {x_mm:.2f} mm (drive) outside the allowed {lo:g} … {hi:g} mm"
            )
        if abs(state.velocity_m_s) > self.speed_max_m_s:
            raise EStopError(
                f"drive speed {abs(state.velocity_m_s):.3f} m/s above the allowed "
                f"{self.speed_max_m_s:.3g} m/s"
            )

    def check_silence(self, silent_s: float) -> None:
        """The gauge stream has been silent for ``silent_s``."""
        if silent_s > self.limits.gauge_timeout_s:
            raise EStopError(
                f"the gauge stream has been silent for {silent_s:.2f} s "
                f"(limit {self.limits.gauge_timeout_s:g} s)"
            )
