"""The drive's mechanical limits: what every motion command is checked against.

Values are the paper's stand (amplitude) and engineering estimates (speed,
acceleration) for a Unidrive SP servo axis; all are overridable in the stand file.
"""

from __future__ import annotations

from dataclasses import dataclass


class LimitError(ValueError):
    """A drive command lies beyond the stand's limits; nothing was moved."""


class InvalidSignalError(ValueError):
    """A signal value that is no valid value of its field (NaN, ≤ 0, ...): bad input.

    Not a LimitError: a limit refuses a motion the drive cannot make (exit 3); this
    refuses a value that describes no motion at all (exit 2).
    """


#: The drive's profile clock (Pr 20.34, 32 bits of 10 µs) wraps after 2³¹ × 10 µs =
#: 21 474.8 s (5.96 h): a profile must end before it does.
PROFILE_CLOCK_MAX_S = 2**31 * 1e-5
#: Dwell times are written in µs to 32-bit parameters (Pr 20.26, 20.27): at most 2147 s.
DWELL_MAX_S = (2**31 - 1) * 1e-6
#: Frequencies are written in µHz (Pr 20.23): below 1 mHz the written value is off by
#: more than 0.1 %, and a cycle lasts over 16 min.
FREQUENCY_MIN_HZ = 1e-3
#: The planners build a few pieces per cycle and the drive's program steps through them:
#: beyond 10⁵ cycles the plan takes seconds and the simulated drive stalls loading it.
CYCLES_MAX = 100_000


@dataclass(frozen=True)
class DriveLimits:
    """Limits of the linear drive, SI units.

    Attributes
    ----------
    amplitude_max_m
        Largest stroke from the rest position, m. 0.090 m [paper].
    speed_max_m_s
        Largest drive speed, m/s. 1.0 m/s [estimate].
    accel_max_m_s2
        Largest drive acceleration, m/s². 10 m/s² [estimate]: twice the weight's
        free-fall acceleration along the incline, so quick returns can slacken the fibre
        as the paper reports, yet the weight is not flung out of its guide.
    """

    amplitude_max_m: float = 0.090
    speed_max_m_s: float = 1.0
    accel_max_m_s2: float = 10.0

    def check_amplitude(self, amplitude_m: float) -> None:
        """Refuse an amplitude that is not positive or exceeds the stroke."""
        if not amplitude_m > 0:
            raise LimitError(f"amplitude must be > 0 mm, got {amplitude_m * 1e3:g} mm")
        if amplitude_m > self.amplitude_max_m * (1 + 1e-12):
            raise LimitError(
                f"amplitude {amplitude_m * 1e3:g} mm exceeds the drive limit "
                f"{self.amplitude_max_m * 1e3:g} mm"
            )

    def check_speed(self, speed_m_s: float, what: str = "peak speed") -> None:
        """Refuse a speed above the drive's limit."""
        if speed_m_s > self.speed_max_m_s * (1 + 1e-9):
            raise LimitError(
                f"{what} {speed_m_s:.4g} m/s exceeds the drive limit {self.speed_max_m_s:g} m/s"
            )

    def check_accel(self, accel_m_s2: float, what: str = "peak acceleration") -> None:
        """Refuse an acceleration above the drive's limit."""
        if accel_m_s2 > self.accel_max_m_s2 * (1 + 1e-9):
            raise LimitError(
                f"{what} {accel_m_s2:.4g} m/s² exceeds the drive limit {self.accel_max_m_s2:g} m/s²"
            )
