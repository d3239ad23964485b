"""The simulated stand: one asyncio loop runs the drive's Modbus server and the gauges.

Drive and gauges share one state: every ``sync()`` advances the simulated drive to the
present sample by sample, feeds its positions to the stand model and sends the frames
that came due. ``sync()`` runs every ``tick_s`` (a pacing loop) and before every Modbus
request, so a command acts at the moment it arrives.

Real time is simulated time paced by a clock: ``ScaledClock(speed)`` runs ``speed``
simulated seconds per wall second (tests use 2–10 ×; the watchdog's 1 s and the
gauges' 2 kHz are simulated time). A stalled loop catches up: no frame is skipped, they
only arrive late — as from a USB-serial adapter.

Use it from Python with ``StandThread`` (a background thread), or as a process with
``labstand stand-sim``.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
import threading
import time
from dataclasses import asdict, dataclass, field
from types import TracebackType
from typing import Any, Protocol

import numpy as np
from pymodbus.server import ModbusSerialServer, ModbusTcpServer

from drivers.calibration import GaugeCalibration
from drivers.gauge_frame import FRAME_SIZE, FRAME_VERSION
from drivers.limits import DriveLimits
from drivers.unidrive_profile import ProfileState
from sim.config import StandConfig
from sim.hardware.drive import SimulatedDrive
from sim.hardware.faults import Fault, FaultKind, FaultPlan
from sim.hardware.gauges import FrontEndSettings, GaugeFrontEnd, PtyWriter
from sim.hardware.modbus_server import make_device, start_rtu_server, start_tcp_server
from sim.hardware.pty import PtyBridge, RawPty, open_raw_pty
from sim.hardware.servo import ServoSettings
from sim.hardware.stand_model import build_stand_model
from sim.params import StandParams

log = logging.getLogger(__name__)

__all__ = ["Clock", "Endpoints", "ScaledClock", "SimulatedStand", "StandSettings", "StandThread"]

_MAX_BLOCK = 1000  # samples per advance when catching up


class Clock(Protocol):
    """Simulated time."""

    def now(self) -> float:
        """Simulated seconds (any origin; only differences matter)."""
        ...


class ScaledClock:
    """``speed`` simulated seconds per second of ``time.monotonic()``."""

    def __init__(self, speed: float = 1.0) -> None:
        if not speed > 0:
            raise ValueError(f"clock speed must be > 0, got {speed:g}")
        self.speed = speed
        self._t0 = time.monotonic()

    def now(self) -> float:
        """Simulated seconds since construction."""
        return (time.monotonic() - self._t0) * self.speed


@dataclass(frozen=True)
class StandSettings:
    """How the simulated stand is served.

    Attributes
    ----------
    modbus
        ``tcp://127.0.0.1:PORT`` (0: any free port), ``rtu`` (a pty pair of its own) or
        ``rtu:PATH`` (serve on an existing serial port, e.g. one end of a socat pair).
    tick_s
        Wall time between pacing steps, s.
    effects
        Effect names switched on in the stand model (``sim.hardware.stand_model``).
    faults
        Faults to inject once the drive runs a profile (``sim.hardware.faults``).
    """

    modbus: str = "tcp://127.0.0.1:0"
    tick_s: float = 0.005
    effects: tuple[str, ...] = ()
    frontend: FrontEndSettings = field(default_factory=FrontEndSettings)
    servo: ServoSettings = field(default_factory=ServoSettings)
    faults: tuple[Fault, ...] = ()


@dataclass(frozen=True)
class Endpoints:
    """Where to connect: ``modbus`` is a URL for ``drivers.unidrive.open_unidrive``."""

    modbus: str
    gauges: str
    rate_hz: float
    speed: float
    frame_bytes: int = FRAME_SIZE
    frame_version: int = FRAME_VERSION

    def to_dict(self) -> dict[str, Any]:
        """Plain values (for the stand-sim JSON line)."""
        return asdict(self)


class SimulatedStand:
    """Simulated Unidrive SP + gauge front end sharing one simulated stand.

    Parameters
    ----------
    params
        The stand model's parameters (the weight's mass included).
    limits
        Limits commissioned on the simulated drive.
    calibration
        Count scaling of the simulated front end.
    """

    def __init__(
        self,
        params: StandParams,
        limits: DriveLimits,
        calibration: GaugeCalibration,
        settings: StandSettings | None = None,
        clock: Clock | None = None,
    ) -> None:
        self.settings = settings or StandSettings()
        self.clock: Clock = clock or ScaledClock()
        rate = self.settings.frontend.rate_hz
        self.drive = SimulatedDrive(limits, rate, self.settings.servo)
        self._params = params
        model = build_stand_model(params, rate, self.settings.effects)
        self.frontend = GaugeFrontEnd(model, calibration, self.settings.frontend)
        self._gauge_pty: RawPty | None = None
        self._bridge: PtyBridge | None = None
        self.writer: PtyWriter | None = None
        self._server: ModbusTcpServer | ModbusSerialServer | None = None
        self._t_zero = 0.0
        self.endpoints: Endpoints | None = None
        #: Fault injection: while True the simulated drive answers no Modbus request.
        self.modbus_muted = False
        #: Fault injection: while True the front end sends no frames.
        self.gauges_silent = False
        self.faults = FaultPlan(self.settings.faults)
        self._fault_ends: dict[FaultKind, float] = {}
        self._garbage = b""

    @classmethod
    def from_config(
        cls,
        config: StandConfig,
        params: str = "final",
        mass_kg: float | None = None,
        settings: StandSettings | None = None,
        clock: Clock | None = None,
    ) -> SimulatedStand:
        """The stand a configuration describes."""
        return cls(
            config.stand_params(params, mass_kg), config.drive, config.gauges, settings, clock
        )

    @property
    def speed(self) -> float:
        """Simulated seconds per wall second."""
        return float(getattr(self.clock, "speed", 1.0))

    async def start(self) -> Endpoints:
        """Open the ptys, start the Modbus server; returns where to connect."""
        # Compile the model's kernels now (the augmented one too, with effects), not in
        # the first Modbus request's time-out: a throwaway copy of the stand's model.
        rate = self.drive.rate_hz
        build_stand_model(self._params, rate, self.settings.effects).advance(np.zeros(2))
        try:
            self._gauge_pty = open_raw_pty()
            self.writer = PtyWriter(self._gauge_pty.master_fd)
            modbus = await self._start_modbus()
        except BaseException:
            await self.close()
            raise
        self._t_zero = self.clock.now()
        self.endpoints = Endpoints(modbus, self._gauge_pty.path, self.drive.rate_hz, self.speed)
        return self.endpoints

    async def _start_modbus(self) -> str:
        device = make_device(self.drive, self.sync, lambda: self.modbus_muted)
        spec = self.settings.modbus
        if spec.startswith("tcp://"):
            host, _, port = spec[len("tcp://") :].rpartition(":")
            server, bound = await start_tcp_server(device, host or "127.0.0.1", int(port or 0))
            self._server = server
            return f"tcp://127.0.0.1:{bound}"
        if spec == "rtu":
            self._bridge = PtyBridge()
            self._bridge.start()
            self._server = await start_rtu_server(device, self._bridge.a.path)
            return f"rtu://{self._bridge.b.path}?baudrate=115200&stopbits=2&parity=N"
        if spec.startswith("rtu:"):
            path = spec[len("rtu:") :]
            self._server = await start_rtu_server(device, path)
            return f"rtu://{path}?baudrate=115200&stopbits=2&parity=N"
        raise ValueError(f"--modbus must be tcp://127.0.0.1:PORT, rtu or rtu:PATH, got {spec!r}")

    def sync(self) -> None:
        """Advance drive, model and gauges to the clock's present; send the frames."""
        if self.writer is None:
            return
        due = math.floor((self.clock.now() - self._t_zero) * self.drive.rate_hz) - self.drive.k
        while due > 0:
            n = min(due, _MAX_BLOCK)
            x = self.drive.advance(n)
            frames = self.frontend.frames(x)
            if not self.gauges_silent and self.writer.write(frames):
                self.frontend.overrun_pending = True
            due -= n
        self._apply_faults()

    def _apply_faults(self) -> None:
        """Start and end the scheduled faults (``StandSettings.faults``)."""
        t = self.drive.t_s
        for kind, end in list(self._fault_ends.items()):
            if t >= end:
                del self._fault_ends[kind]
                self._silence(kind, False)
        for fault in self.faults.due(t, self.drive.profile_state is ProfileState.RUNNING):
            log.warning("simulated stand: fault %s at %.3f s", fault, t)
            if fault.kind is FaultKind.TRIP:
                self.drive.trip(int(fault.value))
            elif fault.kind is FaultKind.GARBAGE:
                rng = np.random.default_rng(int(fault.value))
                self._garbage += rng.integers(0, 256, int(fault.value), np.uint8).tobytes()
            else:
                self._silence(fault.kind, True)
                if math.isfinite(fault.value):
                    self._fault_ends[fault.kind] = t + fault.value
        if self._garbage and self.writer is not None and self.writer.inject(self._garbage):
            self._garbage = b""

    def _silence(self, kind: FaultKind, on: bool) -> None:
        if kind is FaultKind.MODBUS_MUTE:
            self.modbus_muted = on
        else:
            self.gauges_silent = on

    async def serve(self, stop: asyncio.Event) -> None:
        """Pace the stand until ``stop`` is set."""
        tick = self.settings.tick_s
        while not stop.is_set():
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(stop.wait(), tick)
            self.sync()

    async def close(self) -> None:
        """Stop the server and close every pty (idempotent)."""
        if self._server is not None:
            await self._server.shutdown()  # type: ignore[no-untyped-call]
            self._server = None
        if self._bridge is not None:
            self._bridge.close()
            self._bridge = None
        if self._gauge_pty is not None:
            self._gauge_pty.close()
            self._gauge_pty = None
        self.writer = None

    def summary(self) -> dict[str, Any]:
        """Counters for the log / the stand-sim exit line."""
        w = self.writer
        return {
            "t_s": self.drive.t_s,
            "frames": self.frontend.produced,
            "dropped": w.dropped if w else None,
            "trips": [code for _, code in self.drive.trips],
            "enabled": self.drive.enabled,
            "x_mm": self.drive.servo.x_m * 1e3,
        }


class StandThread:
    """A SimulatedStand served from a background thread (for tests and scripts).

    ``with StandThread(stand) as ep: ...`` starts it, waits for the endpoints, and stops
    and joins it on exit. ``call(fn)`` runs ``fn()`` in the stand's loop (thread-safe
    access to the simulated drive).
    """

    # Ready means compiled: a fresh clone's first compile of the stand's model takes tens of
    # seconds on a loaded machine (StandProcess allows as long).
    def __init__(self, stand: SimulatedStand, start_timeout_s: float = 120.0) -> None:
        self.stand = stand
        self._timeout = start_timeout_s
        self._thread = threading.Thread(target=self._run, name="simulated-stand", daemon=True)
        self._ready = threading.Event()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._error: BaseException | None = None

    def start(self) -> Endpoints:
        """Start serving; returns the endpoints."""
        self._thread.start()
        if not self._ready.wait(self._timeout):
            raise TimeoutError("the simulated stand did not start")
        if self._error is not None or self.stand.endpoints is None:
            self._thread.join()
            raise RuntimeError("the simulated stand failed to start") from self._error
        return self.stand.endpoints

    def _run(self) -> None:
        asyncio.run(self._main())

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        try:
            await self.stand.start()
        except BaseException as err:  # reported to start()
            self._error = err
            self._ready.set()
            return
        self._ready.set()
        try:
            await self.stand.serve(self._stop)
        finally:
            await self.stand.close()

    def call(self, fn: Any) -> Any:
        """Run ``fn()`` in the stand's event loop and return its result."""
        if self._loop is None:
            raise RuntimeError("the simulated stand is not running")

        async def wrapped() -> Any:
            return fn()

        return asyncio.run_coroutine_threadsafe(wrapped(), self._loop).result(self._timeout)

    def stop(self) -> None:
        """Stop serving and join the thread (idempotent)."""
        if self._loop is not None and self._stop is not None and not self._loop.is_closed():
            with contextlib.suppress(RuntimeError):
                self._loop.call_soon_threadsafe(self._stop.set)
        if self._thread.is_alive():
            self._thread.join(self._timeout)

    def __enter__(self) -> Endpoints:
        return self.start()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.stop()
