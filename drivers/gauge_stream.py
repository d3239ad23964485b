"""The 2 kHz gauge stream from a serial port: a reader thread, a parser, a queue.

``SerialGaugeStream`` opens the front end's port by path (pyserial; ``/dev/ttyUSB0``, a
pty, or ``loop://`` in parser tests), and a daemon thread reads whatever has arrived
(``in_waiting`` bytes, waiting at most ``read_timeout_s`` for the first), parses it with
``drivers.gauge_frame.FrameParser``, converts counts to N and mm, and puts one numpy
block (``SAMPLE_DTYPE``) per read on a bounded queue. The thread never writes files and
never waits on the consumer: when the queue is full the block is dropped and counted
(the consumer sees the sequence gap). Samples are timed by the device clock; the host
arrival time is kept beside it for latency checks only.

Exceptions::

    Exception
     └── GaugeError                              anything the gauge stream raises
          ├── GaugeConnectionError (+ConnectionError)  the port cannot be opened / vanished
          └── GaugeClosedError (+ClosedError)          used after close()
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from typing import Any, Protocol

import numpy as np
import serial
from numpy.typing import NDArray

from drivers.calibration import GaugeCalibration
from drivers.errors import GaugeError
from drivers.gauge_frame import FrameParser
from drivers.interfaces import SAMPLE_DTYPE, ClosedError, GaugeSource, GaugeStats

log = logging.getLogger(__name__)

__all__ = [
    "GaugeClosedError",
    "GaugeConnectionError",
    "GaugeError",
    "SerialGaugeStream",
    "SerialLike",
]


class GaugeConnectionError(GaugeError, ConnectionError):
    """The gauge port cannot be opened, or it failed while reading."""


class GaugeClosedError(GaugeError, ClosedError):
    """The stream was used after close()."""


class SerialLike(Protocol):
    """The part of ``serial.Serial`` the reader uses."""

    @property
    def in_waiting(self) -> int: ...  # noqa: D102
    def read(self, size: int = 1) -> bytes: ...  # noqa: D102
    def reset_input_buffer(self) -> None: ...  # noqa: D102
    def close(self) -> None: ...  # noqa: D102


class SerialGaugeStream(GaugeSource):
    """Gauge samples from the front end's serial port.

    Parameters
    ----------
    port
        A path or pyserial URL to open, or an open serial-port-like object (it is closed
        with the stream).
    calibration
        Count → N / mm conversion (the stand configuration's ``[gauges]``).
    rate_hz
        The front end's frame rate, Hz.
    baudrate
        Line speed for a real UART (2 kHz × 24 B needs ≥ 480 000 baud); ignored by ptys.
    read_timeout_s
        Longest wait for the first byte of a read; bounds how fast ``close()`` returns.
    block_interval_s
        Shortest time between two reads: bytes arriving meanwhile wait in the port's
        buffer and are parsed together (fewer, larger blocks; at most this much latency).
    queue_blocks
        Blocks the queue holds before dropping (each read makes one block).
    flush_on_open
        Discard what waited in the port before opening (stale frames).
    """

    def __init__(
        self,
        port: str | SerialLike,
        calibration: GaugeCalibration,
        *,
        rate_hz: float = 2000.0,
        baudrate: int = 921_600,
        read_timeout_s: float = 0.05,
        block_interval_s: float = 0.02,
        queue_blocks: int = 10_000,
        flush_on_open: bool = True,
    ) -> None:
        self.rate_hz = rate_hz
        self.calibration = calibration
        self.block_interval_s = block_interval_s
        if isinstance(port, str):
            self.name = f"gauges {port}"
            try:
                self._port: SerialLike = serial.serial_for_url(
                    port, baudrate=baudrate, timeout=read_timeout_s, exclusive=True
                )
            except (serial.SerialException, OSError, ValueError) as err:
                raise GaugeConnectionError(f"gauges: cannot open {port}: {err}") from err
        else:
            self.name = f"gauges {port!r}"
            self._port = port
        if flush_on_open:
            self._port.reset_input_buffer()
        self._parser = FrameParser(rate_hz)
        self._queue: queue.Queue[NDArray[np.void]] = queue.Queue(queue_blocks)
        self._lock = threading.Lock()
        self._dropped_blocks = 0
        self._bytes_read = 0
        self._error: BaseException | None = None
        self._stop = threading.Event()
        self.last_data_s = time.monotonic()
        self._thread = threading.Thread(
            target=self._reader, name=f"{self.name} reader", daemon=True
        )
        self._thread.start()

    # ---- reader thread ---------------------------------------------------------------
    def _reader(self) -> None:
        try:
            while not self._stop.is_set():
                started = time.monotonic()
                waiting = self._port.in_waiting
                data = self._port.read(waiting if waiting else 1)
                if not data:
                    continue
                if not waiting and (more := self._port.in_waiting):
                    data += self._port.read(more)
                self._handle(data, time.monotonic_ns())
                self._stop.wait(self.block_interval_s - (time.monotonic() - started))
        except Exception as err:  # port vanished, driver error: reported to the consumer
            if not self._stop.is_set():
                log.error("%s: reader failed: %s", self.name, err)
                self._error = err

    def _handle(self, data: bytes, t_ns: int) -> None:
        with self._lock:
            frames = self._parser.feed(data)
        self.last_data_s = t_ns / 1e9
        block = np.empty(frames.shape[0], dtype=SAMPLE_DTYPE)
        if frames.shape[0]:
            force, u_mm, x_mm = self.calibration.to_si(
                frames["force"], frames["weight"], frames["drive"]
            )
            block["seq"] = frames["seq"]
            block["t_device_us"] = frames["t_device_us"]
            block["t_host_ns"] = t_ns
            block["force_n"] = force
            block["u_mm"] = u_mm
            block["x_mm"] = x_mm
            block["flags"] = frames["flags"]
        with self._lock:
            self._bytes_read += len(data)
            if not frames.shape[0]:
                return
            try:
                self._queue.put_nowait(block)
            except queue.Full:
                self._dropped_blocks += 1

    # ---- GaugeSource -----------------------------------------------------------------
    def _check_open(self) -> None:
        if self._closed:
            raise GaugeClosedError(f"{self.name}: gauge stream is closed")

    def _read_block(self, timeout_s: float) -> NDArray[np.void] | None:
        try:
            return self._queue.get(timeout=timeout_s) if timeout_s > 0 else self._queue.get_nowait()
        except queue.Empty:
            pass
        if self._error is not None and not self._thread.is_alive():
            err, self._error = self._error, None
            raise GaugeConnectionError(f"{self.name}: reading failed: {err}") from err
        return None

    def drain(self) -> NDArray[np.void]:
        """Every block queued so far, concatenated (no waiting)."""
        self._check_open()
        blocks: list[NDArray[np.void]] = []
        while True:
            try:
                blocks.append(self._queue.get_nowait())
            except queue.Empty:
                break
        return np.concatenate(blocks) if blocks else np.empty(0, dtype=SAMPLE_DTYPE)

    def _stats(self) -> GaugeStats:
        with self._lock:
            c = self._parser.counters
            return GaugeStats(
                frames=c.frames,
                lost=c.lost,
                corrupt=c.corrupt,
                skipped_bytes=c.skipped_bytes,
                overruns=c.overruns,
                dropped_blocks=self._dropped_blocks,
                bytes_read=self._bytes_read,
            )

    def _close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5.0)
        if self._thread.is_alive():  # pragma: no cover - a read that ignores its time-out
            log.warning("%s: reader thread did not stop", self.name)
        self._port.close()

    def __repr__(self) -> str:
        return f"SerialGaugeStream({self.name!r})"


def open_gauges(port: str, calibration: GaugeCalibration, **kwargs: Any) -> SerialGaugeStream:
    """A gauge source on a serial port path (the configuration's choice of backend)."""
    return SerialGaugeStream(port, calibration, **kwargs)
