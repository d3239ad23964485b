"""An in-memory Modbus client for the simulated drive: no server, no socket, no thread.

``InProcessClient`` answers the driver's requests (``drivers.unidrive.ModbusClient``)
straight from a ``SimulatedDrive`` through the same request handlers the Modbus server
uses, returning pymodbus response PDUs (error replies included). Unit tests drive time
themselves (``drive.advance(n)``) and can make the link fail on demand.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from pymodbus.constants import ExcCodes
from pymodbus.exceptions import ConnectionException
from pymodbus.pdu import ExceptionResponse, ModbusPDU
from pymodbus.pdu.register_message import (
    ReadHoldingRegistersResponse,
    ReadWriteMultipleRegistersResponse,
    WriteMultipleRegistersResponse,
)

from sim.hardware.drive import SimulatedDrive
from sim.hardware.modbus_server import read_request, write_request

__all__ = ["InProcessClient"]


class InProcessClient:
    """A pymodbus-like sync client wired to a simulated drive.

    Parameters
    ----------
    drive
        The drive that answers.
    before_request
        Called before every request (e.g. to advance simulated time).

    Attributes
    ----------
    fail_next
        Exceptions to raise instead of answering, one per request (``ModbusIOException``
        for a time-out, ``ConnectionException`` for a lost link).
    requests
        (function code, address, count or values) of every request answered.
    """

    def __init__(
        self, drive: SimulatedDrive, before_request: Callable[[], None] | None = None
    ) -> None:
        self.drive = drive
        self._before = before_request
        self.fail_next: list[Exception] = []
        self.requests: list[tuple[int, int, object]] = []
        self.connected = False
        self.connects = 0

    def connect(self) -> bool:
        """Always succeeds."""
        self.connected = True
        self.connects += 1
        return True

    def close(self) -> None:
        """Forget the connection."""
        self.connected = False

    def _enter(self) -> None:
        if not self.connected:
            raise ConnectionException("not connected")
        if self.fail_next:
            raise self.fail_next.pop(0)
        if self._before is not None:
            self._before()

    def read_holding_registers(
        self,
        address: int,
        *,
        count: int = 1,
        device_id: int = 1,
        no_response_expected: bool = False,
    ) -> ModbusPDU:
        """FC 3."""
        self._enter()
        self.requests.append((3, address, count))
        words = read_request(self.drive, address, count)
        if isinstance(words, ExcCodes):
            return ExceptionResponse(3, words, device_id)
        return ReadHoldingRegistersResponse(registers=words, dev_id=device_id)

    def write_registers(
        self,
        address: int,
        values: Sequence[int],
        *,
        device_id: int = 1,
        no_response_expected: bool = False,
    ) -> ModbusPDU:
        """FC 16."""
        self._enter()
        self.requests.append((16, address, list(values)))
        error = write_request(self.drive, address, list(values))
        if error is not None:
            return ExceptionResponse(16, error, device_id)
        return WriteMultipleRegistersResponse(address=address, count=len(values), dev_id=device_id)

    def readwrite_registers(
        self,
        *,
        read_address: int = 0,
        read_count: int = 0,
        write_address: int = 0,
        address: int | None = None,
        values: Sequence[int] | None = None,
        device_id: int = 1,
        no_response_expected: bool = False,
    ) -> ModbusPDU:
        """FC 23: write first, then read."""
        self._enter()
        self.requests.append((23, write_address, list(values or [])))
        error = write_request(self.drive, write_address, list(values or []))
        if error is not None:
            return ExceptionResponse(23, error, device_id)
        words = read_request(self.drive, read_address, read_count)
        if isinstance(words, ExcCodes):
            return ExceptionResponse(23, words, device_id)
        return ReadWriteMultipleRegistersResponse(registers=words, dev_id=device_id)
