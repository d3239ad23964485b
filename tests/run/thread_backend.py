"""A device backend written for the registry test: the simulated stand in a thread.

One module and one ``BACKENDS`` line make it a backend ``labstand run --backend`` can
use: the simulated stand served from a thread of this process (real Modbus TCP on
127.0.0.1 and a real pty), opened with the stand's drivers.
"""

from __future__ import annotations

from typing import Any

from labstand.backends.stand import open_wire_devices
from labstand.session.devices import DeviceRequest, Devices
from recordings.schema import Backend
from sim.hardware.stand import SimulatedStand, StandThread


def open_thread(request: DeviceRequest) -> Devices:
    """Start the simulated stand in a thread and open its devices."""
    stand = SimulatedStand.from_config(request.config, mass_kg=request.mass_kg)
    thread = StandThread(stand)
    ep = thread.start()
    try:
        devices = open_wire_devices(ep.modbus, ep.gauges, request.config, Backend.SIM)
    except BaseException:
        thread.stop()
        raise

    def stop() -> dict[str, Any]:
        thread.stop()
        return {"enabled": stand.drive.enabled, "trips": [c for _, c in stand.drive.trips]}

    devices.stopper = stop
    devices.where = f"simulated stand in a thread: {devices.where}"
    return devices
