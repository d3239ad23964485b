"""Hardware drivers and the drive-signal generators.

An acquisition session depends on two small interfaces (``drivers.interfaces``):
``DriveInterface`` (implemented by ``UnidriveSP``, Modbus TCP or RTU, built with
``open_unidrive(url, limits)``) and ``GaugeSource`` (implemented by
``SerialGaugeStream``, built with ``open_gauges(path, calibration)``). Which port or
address they use is configuration; the simulated stand serves the same protocols.

Exceptions: one root, ``DeviceError`` (``drivers.errors``, tree in its docstring), with
``DriveError``, ``GaugeError``, ``DeviceTimeoutError`` and ``ClosedError`` under it;
``LimitError`` (a ValueError) refuses a command before anything moves.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Lazy re-exports (PEP 562): importing one driver module (``drivers.signals`` for the
# model, say) must not load pymodbus and pyserial through this package.
_EXPORTS = {
    "GaugeCalibration": "drivers.calibration",
    "DeviceError": "drivers.errors",
    "DeviceTimeoutError": "drivers.errors",
    "GaugeError": "drivers.errors",
    "SerialGaugeStream": "drivers.gauge_stream",
    "open_gauges": "drivers.gauge_stream",
    "SAMPLE_DTYPE": "drivers.interfaces",
    "ClosedError": "drivers.errors",
    "DriveInterface": "drivers.interfaces",
    "DriveState": "drivers.interfaces",
    "GaugeSource": "drivers.interfaces",
    "GaugeStats": "drivers.interfaces",
    "DriveLimits": "drivers.limits",
    "LimitError": "drivers.limits",
    "DriveProfile": "drivers.signals",
    "Shape": "drivers.signals",
    "SignalSpec": "drivers.signals",
    "plan_motion": "drivers.signals",
    "DriveError": "drivers.errors",
    "UnidriveSP": "drivers.unidrive",
    "open_unidrive": "drivers.unidrive",
    "ProfileState": "drivers.unidrive_profile",
}

if TYPE_CHECKING:
    from drivers.calibration import GaugeCalibration
    from drivers.errors import ClosedError, DeviceError, DeviceTimeoutError, DriveError, GaugeError
    from drivers.gauge_stream import SerialGaugeStream, open_gauges
    from drivers.interfaces import (
        SAMPLE_DTYPE,
        DriveInterface,
        DriveState,
        GaugeSource,
        GaugeStats,
    )
    from drivers.limits import DriveLimits, LimitError
    from drivers.signals import DriveProfile, Shape, SignalSpec, plan_motion
    from drivers.unidrive import UnidriveSP, open_unidrive
    from drivers.unidrive_profile import ProfileState


# The same PEP 562 hook in every package __init__ (drivers, sim, sim.effects, sim.hardware,
# recordings): a shared helper would have to live in the lowest layer, drivers.
def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'drivers' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)


__all__ = [
    "SAMPLE_DTYPE",
    "ClosedError",
    "DeviceError",
    "DeviceTimeoutError",
    "DriveError",
    "DriveInterface",
    "DriveLimits",
    "DriveProfile",
    "DriveState",
    "GaugeCalibration",
    "GaugeError",
    "GaugeSource",
    "GaugeStats",
    "LimitError",
    "ProfileState",
    "SerialGaugeStream",
    "Shape",
    "SignalSpec",
    "UnidriveSP",
    "open_gauges",
    "open_unidrive",
    "plan_motion",
]
