"""Backend ``stand``: the drive and the gauge port of the stand file's ``[devices]``.

``open_wire_devices`` is shared with ``sim``, which opens the same drivers on the
simulated stand's endpoints: the Unidrive SP over Modbus (TCP or RTU) and the 2 kHz
gauge stream on a serial port.
"""

from __future__ import annotations

from drivers.errors import DriveError, GaugeError
from drivers.gauge_stream import open_gauges
from drivers.unidrive import open_unidrive
from labstand.errors import CommandError, ExitCode
from labstand.session.devices import DeviceRequest, Devices
from recordings.schema import Backend
from sim.config import StandConfig

__all__ = ["open_stand", "open_wire_devices"]


def open_stand(request: DeviceRequest) -> Devices:
    """The devices of the stand file's ``[devices]`` table.

    Raises
    ------
    CommandError
        No ``[devices]`` or effects asked for (usage); a device cannot be opened.
    """
    config = request.config
    if config.devices is None:
        raise CommandError(
            f"{config.source}: no [devices] table, so no stand to run; add one "
            "(docs/configuration.md) or use --backend sim",
            ExitCode.USAGE,
        )
    if request.effects:
        raise CommandError("--effect needs --backend sim", ExitCode.USAGE)
    dev = config.devices
    return open_wire_devices(dev.drive, dev.gauges, config, Backend.STAND, dev.gauges_baudrate)


def open_wire_devices(
    drive_url: str,
    gauge_port: str,
    config: StandConfig,
    backend: Backend,
    baudrate: int = 921_600,
) -> Devices:
    """The Unidrive SP at ``drive_url`` and the gauge stream on ``gauge_port``."""
    try:
        drive = open_unidrive(drive_url, config.drive)
    except DriveError as err:
        raise CommandError(f"cannot reach the drive: {err}") from err
    try:
        gauges = open_gauges(
            gauge_port, config.gauges, rate_hz=config.sample_rate_hz, baudrate=baudrate
        )
    except GaugeError as err:
        drive.close()
        raise CommandError(f"cannot open the gauges: {err}") from err
    where = f"drive {drive_url}, gauges {gauge_port}"
    return Devices(drive, gauges, backend, where)
