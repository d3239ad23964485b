"""Builds the devices a session runs on: the stand's, or the simulated stand's.

The only place that knows the backends apart. ``stand`` opens the drive and the gauge
port named by the stand file's ``[devices]`` table. ``sim`` starts ``labstand stand-sim``
as a child process (``StandProcess``: Modbus TCP on 127.0.0.1 and a pty, the same wire
protocols as the stand), opens the same drivers on its endpoints, and stops it when the
devices are closed. Either way the session gets a ``DriveInterface`` and a
``GaugeSource``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drivers.errors import DriveError, GaugeError
from drivers.gauge_stream import open_gauges
from drivers.interfaces import DriveInterface, GaugeSource
from drivers.unidrive import open_unidrive
from labstand.errors import CommandError, ExitCode
from recordings.schema import Backend
from sim.config import StandConfig
from sim.hardware.process import StandProcess, StandStartError

log = logging.getLogger(__name__)

__all__ = ["BACKENDS", "Devices", "default_backend", "open_devices"]

BACKENDS = ("stand", "sim")


@dataclass
class Devices:
    """A drive, a gauge source, and what they are.

    Attributes
    ----------
    where
        Where the devices are, one line for the operator.
    sim
        The simulated stand's process (backend ``sim``), else None.
    sim_summary
        The simulated stand's last line after ``stop_sim`` (its drive's final state).
    """

    drive: DriveInterface
    gauges: GaugeSource
    backend: Backend
    where: str
    sim: StandProcess | None = None
    sim_summary: dict[str, Any] = field(default_factory=dict)

    def stop_sim(self) -> dict[str, Any]:
        """Stop the simulated stand (if any); returns its final summary."""
        if self.sim is not None and self.sim.process is not None:
            self.sim.stop()
            self.sim_summary = dict(self.sim.stopped)
            self.sim = None
        return self.sim_summary

    def close(self) -> None:
        """Close both drivers (the drive disables on close), then stop the simulation."""
        try:
            self.drive.close()
        finally:
            try:
                self.gauges.close()
            finally:
                self.stop_sim()


def default_backend(config: StandConfig) -> str:
    """``stand`` when the stand file says where the devices are, else ``sim``."""
    return "stand" if config.devices is not None else "sim"


def open_devices(
    backend: str,
    config: StandConfig,
    *,
    mass_kg: float,
    stand_file: Path | None = None,
    effects: tuple[str, ...] = (),
    sim_args: tuple[str, ...] = (),
) -> Devices:
    """Open the devices of a backend.

    Parameters
    ----------
    backend
        ``stand`` or ``sim``.
    config
        The stand configuration (limits, calibration, ``[devices]``).
    mass_kg
        The weight on the stand, kg (the simulated stand simulates it).
    stand_file
        The stand file, passed on to the simulated stand.
    effects
        Effects the simulated stand switches on (``NAME[:param=value,...]``).
    sim_args
        Further ``labstand stand-sim`` options (tests: ``--fault``).

    Raises
    ------
    CommandError
        No ``[devices]`` for the stand (usage), or a device cannot be opened (failure).
    """
    if backend == "stand":
        if config.devices is None:
            raise CommandError(
                f"{config.source}: no [devices] table, so no stand to run; add one "
                "(docs/configuration.md) or use --backend sim",
                ExitCode.USAGE,
            )
        if effects:
            raise CommandError("--effect needs --backend sim", ExitCode.USAGE)
        dev = config.devices
        return _open(dev.drive, dev.gauges, config, Backend.STAND, dev.gauges_baudrate)
    if backend != "sim":
        raise CommandError(f"unknown backend {backend!r}; one of {', '.join(BACKENDS)}")
    args = ["--mass-kg", repr(mass_kg)]
    if stand_file is not None:
        args += ["--stand", str(stand_file)]
    for text in effects:
        args += ["--effect", text]
    sim = StandProcess([*args, *sim_args])
    try:
        ep = sim.start()
    except StandStartError as err:
        raise CommandError(str(err)) from None
    try:
        devices = _open(ep["modbus"], ep["gauges"], config, Backend.SIM)
    except BaseException:
        sim.stop()
        raise
    devices.sim = sim
    devices.where = f"simulated stand (pid {ep['pid']}): {devices.where}"
    return devices


def _open(
    drive_url: str,
    gauge_port: str,
    config: StandConfig,
    backend: Backend,
    baudrate: int = 921_600,
) -> Devices:
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
