"""The devices a session runs on, opened by backend name from the ``BACKENDS`` registry.

A backend is one module with a factory ``open_NAME(request: DeviceRequest) -> Devices``
and one line in ``BACKENDS`` (python-can's ``BACKENDS`` dict): the module is imported
only when the backend is chosen, so this package never imports a concrete driver (an
import-linter contract). ``stand`` opens the stand file's ``[devices]``
(``labstand.backends.stand``); ``sim`` starts the simulated stand as a child process and
opens the same drivers on its endpoints (``labstand.backends.sim``). Either way the
session gets a ``DriveInterface`` and a ``GaugeSource``.
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drivers.interfaces import DriveInterface, GaugeSource
from labstand.errors import CommandError, ExitCode
from recordings.schema import Backend
from sim.config import StandConfig

log = logging.getLogger(__name__)

__all__ = [
    "BACKENDS",
    "BackendFactory",
    "DeviceRequest",
    "Devices",
    "backend_factory",
    "default_backend",
    "open_devices",
]

#: Backend name → (module, factory). A new backend: its module, and one line here.
BACKENDS: dict[str, tuple[str, str]] = {
    "stand": ("labstand.backends.stand", "open_stand"),
    "sim": ("labstand.backends.sim", "open_sim"),
}


@dataclass
class Devices:
    """A drive, a gauge source, and what they are.

    Attributes
    ----------
    where
        Where the devices are, one line for the operator.
    stopper
        Stops what the backend started for the devices (the simulated stand's process)
        and returns its last word; None when there is nothing to stop.
    sim_summary
        The simulated stand's last line after ``stop_sim`` (its drive's final state).
    """

    drive: DriveInterface
    gauges: GaugeSource
    backend: Backend
    where: str
    stopper: Callable[[], dict[str, Any]] | None = None
    sim_summary: dict[str, Any] = field(default_factory=dict)

    def stop_sim(self) -> dict[str, Any]:
        """Stop what the backend started (if anything); returns its final summary."""
        if self.stopper is not None:
            stopper, self.stopper = self.stopper, None
            self.sim_summary = stopper()
        return self.sim_summary

    def close(self) -> None:
        """Close both drivers (the drive disables on close), then stop the backend."""
        try:
            self.drive.close()
        finally:
            try:
                self.gauges.close()
            finally:
                self.stop_sim()


@dataclass(frozen=True)
class DeviceRequest:
    """What a backend factory is asked for.

    Attributes
    ----------
    config
        The stand configuration (limits, calibration, ``[devices]``).
    mass_kg
        The weight on the stand, kg (the simulated stand simulates it).
    stand_file
        The stand file, passed on to a simulated stand.
    effects
        Effects a simulated stand switches on (``NAME[:param=value,...]``).
    sim_args
        Further ``labstand stand-sim`` options (tests: ``--fault``).
    """

    config: StandConfig
    mass_kg: float
    stand_file: Path | None = None
    effects: tuple[str, ...] = ()
    sim_args: tuple[str, ...] = ()


#: Opens a backend's devices; raises CommandError (usage or failure) when it cannot.
BackendFactory = Callable[[DeviceRequest], Devices]


def default_backend(config: StandConfig) -> str:
    """``stand`` when the stand file says where the devices are, else ``sim``."""
    return "stand" if config.devices is not None else "sim"


def backend_factory(backend: str) -> BackendFactory:
    """The factory registered for ``backend`` (its module imported now).

    Raises
    ------
    CommandError
        An unknown backend name (usage).
    """
    try:
        module, name = BACKENDS[backend]
    except KeyError:
        known = ", ".join(BACKENDS)
        raise CommandError(f"unknown backend {backend!r}; one of {known}", ExitCode.USAGE) from None
    factory: BackendFactory = getattr(importlib.import_module(module), name)
    return factory


def open_devices(
    backend: str,
    config: StandConfig,
    *,
    mass_kg: float,
    stand_file: Path | None = None,
    effects: tuple[str, ...] = (),
    sim_args: tuple[str, ...] = (),
) -> Devices:
    """Open the devices of a backend (``DeviceRequest`` describes the arguments).

    Raises
    ------
    CommandError
        An unknown backend, or one the stand cannot have (usage); a device that cannot
        be opened (failure).
    """
    request = DeviceRequest(config, mass_kg, stand_file, tuple(effects), tuple(sim_args))
    return backend_factory(backend)(request)
