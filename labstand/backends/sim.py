"""Backend ``sim``: the simulated stand as a child process, behind the stand's drivers.

``StandProcess`` starts ``labstand stand-sim`` (Modbus TCP on 127.0.0.1 and a pty, the
same wire protocols as the stand); the same drivers as ``stand`` open its endpoints, and
closing the devices stops it and keeps its last word (the drive's final state).
"""

from __future__ import annotations

from typing import Any

from labstand.backends.stand import open_wire_devices
from labstand.errors import CommandError
from labstand.session.devices import DeviceRequest, Devices
from recordings.schema import Backend
from sim.hardware.process import StandProcess, StandStartError

__all__ = ["open_sim"]


def open_sim(request: DeviceRequest) -> Devices:
    """Start the simulated stand and open its devices.

    Raises
    ------
    CommandError
        The simulated stand did not start, or its devices cannot be opened.
    """
    args = ["--mass-kg", repr(request.mass_kg)]
    if request.stand_file is not None:
        args += ["--stand", str(request.stand_file)]
    for text in request.effects:
        args += ["--effect", text]
    sim = StandProcess([*args, *request.sim_args])
    try:
        ep = sim.start()
    except StandStartError as err:
        raise CommandError(str(err)) from None
    try:
        devices = open_wire_devices(ep["modbus"], ep["gauges"], request.config, Backend.SIM)
    except BaseException:
        sim.stop()
        raise
    devices.stopper = lambda: _stop(sim)
    devices.where = f"simulated stand (pid {ep['pid']}): {devices.where}"
    return devices


def _stop(sim: StandProcess) -> dict[str, Any]:
    sim.stop()
    return dict(sim.stopped)
