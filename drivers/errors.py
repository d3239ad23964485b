"""The drivers' error root: what a session catches without knowing which device it has.

Exceptions (each also inherits the matching built-in, as python-can's do)::

    Exception
     └── DeviceError              anything a device driver raises
          ├── DriveError          the drive (drivers.unidrive_wire adds connection,
          │    │                  reply, address, value and tripped errors under it)
          │    └── DriveNotReadyError  enable() before check_limits() passed
          ├── GaugeError          the gauge stream (drivers.gauge_stream adds more)
          ├── DeviceTimeoutError  (also TimeoutError) a device did not answer in time
          └── ClosedError         (also RuntimeError) a driver used after close()
    ValueError
     └── LimitError               a command beyond the drive's limits (drivers.limits;
                                  refused before anything moves, not a device fault)
"""

from __future__ import annotations

__all__ = [
    "ClosedError",
    "DeviceError",
    "DeviceTimeoutError",
    "DriveError",
    "DriveNotReadyError",
    "GaugeError",
]


class DeviceError(Exception):
    """Anything a device driver raises."""


class DriveError(DeviceError):
    """Anything the drive driver raises."""


class DriveNotReadyError(DriveError):
    """``enable()`` before the drive's limits were checked on this connection."""


class GaugeError(DeviceError):
    """Anything the gauge stream raises."""


class DeviceTimeoutError(DeviceError, TimeoutError):
    """A device did not answer within its time-out."""


class ClosedError(DeviceError, RuntimeError):
    """A driver was used after ``close()``."""
