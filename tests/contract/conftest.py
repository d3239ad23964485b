"""Devices for the contract suite: the simulated stand over real wires, or the real stand.

One behaviour suite (``test_drive_contract.py``, ``test_gauge_contract.py``, in the manner
of python-can's ``back2back_test.py``) runs against every backend this module yields:

* ``sim-tcp``: the simulated drive behind a real Modbus TCP server on 127.0.0.1;
* ``sim-rtu``: the same over Modbus RTU through a socat pty pair (the driver on one end,
  the server on the other, as on an RS485 adapter);
* ``sim-pty``: the simulated gauge front end streaming 2 kHz frames into a raw pty;
* ``hardware``: the devices named by the ``[devices]`` table of the stand file in
  ``LABSTAND_HARDWARE`` (marked ``hardware``; skipped when the variable is unset).
  ``LABSTAND_HARDWARE=my-stand.toml .venv/bin/python -m pytest -m hardware tests/contract``

A rig carries what the suite needs beyond the interface: how to open a fresh connection,
how to let the device's own time pass untouched, and — where it can be done — how to
make the device fall silent. The real stand cannot be silenced from here, so those
tests skip there.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from drivers.gauge_stream import open_gauges
from drivers.interfaces import DriveInterface, GaugeSource
from drivers.unidrive import open_unidrive
from sim.config import StandConfig, default_config, load_config
from sim.hardware.stand import ScaledClock, SimulatedStand, StandSettings, StandThread
from tests.hardware_sim.leakcheck import no_leaks
from tests.ptys import socat_ptys

__all__ = ["DriveRig", "GaugeRig", "no_leaks"]

HARDWARE_ENV = "LABSTAND_HARDWARE"
#: The driver's reply time-out per attempt and its extra attempts (open_unidrive's).
TIMEOUT_S, RETRIES = 0.25, 2


def _hardware_config() -> StandConfig:
    path = os.environ.get(HARDWARE_ENV, "")
    if not path:
        pytest.skip(f"{HARDWARE_ENV} names no stand file")
    config = load_config(Path(path))
    if config.devices is None:
        pytest.fail(f"{path}: no [devices] table; the hardware suite needs the stand's devices")
    return config


_HARDWARE = pytest.param(
    "hardware",
    marks=[
        pytest.mark.hardware,
        pytest.mark.skipif(not os.environ.get(HARDWARE_ENV), reason=f"{HARDWARE_ENV} unset"),
    ],
)


@dataclass
class DriveRig:
    """A drive backend under test.

    Attributes
    ----------
    open
        A fresh connection (a ``DriveInterface``; the test closes it).
    quiet
        Let this many seconds of the drive's own time pass without touching it.
    mute
        Make the drive stop (True) or resume (False) answering; None if impossible.
    timeout_s
        The longest a call may take before it must raise ``DeviceTimeoutError``, s.
    """

    open: Callable[[], DriveInterface]
    quiet: Callable[[float], None]
    mute: Callable[[bool], None] | None
    timeout_s: float = TIMEOUT_S * (RETRIES + 1)


@dataclass
class GaugeRig:
    """A gauge backend under test (see DriveRig); ``silence`` stops the stream."""

    open: Callable[[], GaugeSource]
    rate_hz: float
    silence: Callable[[bool], None] | None


def _stand(modbus: str) -> StandThread:
    stand = SimulatedStand.from_config(
        default_config(), settings=StandSettings(modbus=modbus), clock=ScaledClock(1.0)
    )
    return StandThread(stand)


def _wait_drive_time(thread: StandThread, seconds: float) -> None:
    """Wait until the simulated drive's clock has advanced by ``seconds``."""
    drive = thread.stand.drive
    start = drive.t_s
    deadline = time.monotonic() + seconds * 10 + 10.0
    while drive.t_s - start < seconds:
        if time.monotonic() > deadline:
            pytest.fail(f"the simulated drive's clock did not advance {seconds:g} s")
        time.sleep(0.01)


def _set_muted(thread: StandThread, on: bool) -> None:
    thread.stand.modbus_muted = on


@pytest.fixture(scope="module")
def _socat_pair(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[str, str]]:
    with socat_ptys(tmp_path_factory.mktemp("rtu")) as pair:
        yield pair


@pytest.fixture(scope="module", params=["sim-tcp", "sim-rtu", _HARDWARE])
def drive_rig(request: pytest.FixtureRequest) -> Iterator[DriveRig]:
    """Each drive backend in turn."""
    if request.param == "hardware":
        config = _hardware_config()
        assert config.devices is not None
        url = config.devices.drive
        yield DriveRig(
            lambda: open_unidrive(url, config.drive, timeout_s=TIMEOUT_S, retries=RETRIES),
            time.sleep,  # the real drive's time is wall time
            None,
        )
        return
    limits = default_config().drive
    if request.param == "sim-rtu":
        server, client = request.getfixturevalue("_socat_pair")
        thread = _stand(f"rtu:{server}")
        thread.start()
        url = f"rtu://{client}?baudrate=115200&stopbits=2"
    else:
        thread = _stand("tcp://127.0.0.1:0")
        url = thread.start().modbus
    try:
        yield DriveRig(
            lambda: open_unidrive(url, limits, timeout_s=TIMEOUT_S, retries=RETRIES),
            lambda s: _wait_drive_time(thread, s),
            lambda on: _set_muted(thread, on),
        )
    finally:
        thread.stop()


@pytest.fixture(scope="module", params=["sim-pty", _HARDWARE])
def gauge_rig(request: pytest.FixtureRequest) -> Iterator[GaugeRig]:
    """Each gauge backend in turn."""
    if request.param == "hardware":
        config = _hardware_config()
        assert config.devices is not None
        dev = config.devices
        yield GaugeRig(
            lambda: open_gauges(
                dev.gauges,
                config.gauges,
                rate_hz=config.sample_rate_hz,
                baudrate=dev.gauges_baudrate,
            ),
            config.sample_rate_hz,
            None,
        )
        return
    config = default_config()
    thread = _stand("tcp://127.0.0.1:0")
    path = thread.start().gauges

    def silence(on: bool) -> None:
        thread.stand.gauges_silent = on

    try:
        yield GaugeRig(
            lambda: open_gauges(path, config.gauges, rate_hz=config.sample_rate_hz),
            config.sample_rate_hz,
            silence,
        )
    finally:
        thread.stand.gauges_silent = False
        thread.stop()
