"""The simulated stand on real wire protocols (docs/hardware-design.md).

A simulated Unidrive SP (pymodbus server: TCP on 127.0.0.1 or RTU on a pty) and a
simulated gauge front end (2 kHz binary frames on a raw pty) share one simulated stand:
the gauges see the position the simulated drive really ran, through the stand model.

From Python::

    from sim.config import default_config
    from sim.hardware import SimulatedStand, StandThread

    with StandThread(SimulatedStand.from_config(default_config())) as endpoints:
        drive = open_unidrive(endpoints.modbus, limits)      # drivers.unidrive
        gauges = open_gauges(endpoints.gauges, calibration)  # drivers.gauge_stream

As a process: ``labstand stand-sim --json`` (see labstand/commands/stand_sim.py).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Lazy re-exports (PEP 562): importing one module of the package (``sim.hardware.errors``,
# say) must not load the heavy ones (numba, scipy, pandas, h5py, ...) through it.
# A name here must not name both an object and a submodule (importing the submodule
# would rebind it to the module): sim.identify, whose ``diagnose`` is both, stays eager.
_EXPORTS = {
    "SimulatedDrive": "sim.hardware.drive",
    "Fault": "sim.hardware.faults",
    "FaultKind": "sim.hardware.faults",
    "parse_fault": "sim.hardware.faults",
    "FrontEndSettings": "sim.hardware.gauges",
    "GaugeFrontEnd": "sim.hardware.gauges",
    "StandModel": "sim.hardware.gauges",
    "InProcessClient": "sim.hardware.inprocess",
    "ServoSettings": "sim.hardware.servo",
    "Clock": "sim.hardware.stand",
    "Endpoints": "sim.hardware.stand",
    "ScaledClock": "sim.hardware.stand",
    "SimulatedStand": "sim.hardware.stand",
    "StandSettings": "sim.hardware.stand",
    "StandThread": "sim.hardware.stand",
    "available_effects": "sim.hardware.stand_model",
    "build_stand_model": "sim.hardware.stand_model",
}

if TYPE_CHECKING:
    from sim.hardware.drive import SimulatedDrive
    from sim.hardware.faults import Fault, FaultKind, parse_fault
    from sim.hardware.gauges import FrontEndSettings, GaugeFrontEnd, StandModel
    from sim.hardware.inprocess import InProcessClient
    from sim.hardware.servo import ServoSettings
    from sim.hardware.stand import (
        Clock,
        Endpoints,
        ScaledClock,
        SimulatedStand,
        StandSettings,
        StandThread,
    )
    from sim.hardware.stand_model import available_effects, build_stand_model


# The same PEP 562 hook in every package __init__ (drivers, sim, sim.effects, sim.hardware,
# recordings): a shared helper would have to live in the lowest layer, drivers.
def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'sim.hardware' has no attribute {name!r}")
    if module == f"{__name__}.{name}":  # a submodule
        return importlib.import_module(module)
    return getattr(importlib.import_module(module), name)


__all__ = [
    "Clock",
    "Endpoints",
    "Fault",
    "FaultKind",
    "FrontEndSettings",
    "GaugeFrontEnd",
    "InProcessClient",
    "ScaledClock",
    "ServoSettings",
    "SimulatedDrive",
    "SimulatedStand",
    "StandModel",
    "StandSettings",
    "StandThread",
    "available_effects",
    "build_stand_model",
    "parse_fault",
]
