"""Hardware drivers and the drive-signal generators.

Exceptions::

    ValueError
     └── LimitError      a command beyond the drive's limits (nothing moved)
"""

from drivers.calibration import GaugeCalibration
from drivers.limits import DriveLimits, LimitError
from drivers.signals import DriveProfile, Shape, SignalSpec, plan_motion

__all__ = [
    "DriveLimits",
    "DriveProfile",
    "GaugeCalibration",
    "LimitError",
    "Shape",
    "SignalSpec",
    "plan_motion",
]
