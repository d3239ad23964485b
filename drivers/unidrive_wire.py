"""The Unidrive SP driver's wire side: exceptions, the client it needs, register codecs.

The exception tree is drawn in drivers/unidrive.py, which re-exports everything here.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from pymodbus.client.mixin import ModbusClientMixin
from pymodbus.pdu import ModbusPDU

from drivers.errors import DeviceTimeoutError, DriveError
from drivers.interfaces import ClosedError
from drivers.unidrive_profile import RejectReason

__all__ = [
    "DriveAddressError",
    "DriveClosedError",
    "DriveConnectionError",
    "DriveError",
    "DriveProfileError",
    "DriveReplyError",
    "DriveTimeoutError",
    "DriveTrippedError",
    "DriveValueError",
    "ModbusClient",
    "decode_registers",
    "encode_registers",
    "exception_text",
]


class DriveConnectionError(DriveError, ConnectionError):
    """The drive cannot be reached (port, address, cable)."""


class DriveTimeoutError(DriveError, DeviceTimeoutError):
    """The drive did not answer within the time-out, after every retry."""


class DriveReplyError(DriveError):
    """The drive answered with a Modbus exception."""

    def __init__(self, message: str, exception_code: int) -> None:
        super().__init__(message)
        self.exception_code = exception_code


class DriveAddressError(DriveReplyError, LookupError):
    """Exception 2: unknown parameter, read-only parameter, or more than 16 registers."""


class DriveValueError(DriveReplyError, ValueError):
    """Exception 3: the drive did not accept a value."""


class DriveTrippedError(DriveError):
    """The drive is tripped; ``trip_code`` says why."""

    def __init__(self, message: str, trip_code: int) -> None:
        super().__init__(message)
        self.trip_code = trip_code


class DriveProfileError(DriveError, ValueError):
    """The drive program refused a profile (``reason``)."""

    def __init__(self, message: str, reason: RejectReason) -> None:
        super().__init__(message)
        self.reason = reason


class DriveClosedError(DriveError, ClosedError):
    """The driver was used after close()."""


class ModbusClient(Protocol):
    """The part of a pymodbus sync client the driver uses."""

    def connect(self) -> bool: ...  # noqa: D102
    def close(self) -> None: ...  # noqa: D102
    def read_holding_registers(  # noqa: D102
        self,
        address: int,
        *,
        count: int = 1,
        device_id: int = 1,
        no_response_expected: bool = False,
    ) -> ModbusPDU: ...
    def write_registers(  # noqa: D102
        self,
        address: int,
        values: Sequence[int],
        *,
        device_id: int = 1,
        no_response_expected: bool = False,
    ) -> ModbusPDU: ...
    def readwrite_registers(  # noqa: D102
        self,
        *,
        read_address: int = 0,
        read_count: int = 0,
        write_address: int = 0,
        address: int | None = None,
        values: Sequence[int] | None = None,
        device_id: int = 1,
        no_response_expected: bool = False,
    ) -> ModbusPDU: ...


_EXCEPTION_TEXT = {
    1: "illegal function",
    2: "illegal data address: unknown or read-only parameter, or more than 16 registers",
    3: "illegal data value",
    4: "device failure",
    6: "device busy",
}
_DT = ModbusClientMixin.DATATYPE


def exception_text(code: int) -> str:
    """What a Modbus exception code means for this drive."""
    return _EXCEPTION_TEXT.get(code, "exception")


def decode_registers(registers: Sequence[int], width: int) -> list[int]:
    """Registers → signed raw parameter values (32-bit: high word first)."""
    kind = _DT.INT32 if width == 32 else _DT.INT16
    out = ModbusClientMixin.convert_from_registers(list(registers), kind, word_order="big")
    return [int(v) for v in out] if isinstance(out, list) else [int(out)]


def encode_registers(raws: Sequence[int], width: int) -> list[int]:
    """Signed raw parameter values → registers (32-bit: high word first)."""
    kind = _DT.INT32 if width == 32 else _DT.INT16
    return ModbusClientMixin.convert_to_registers(list(raws), kind, word_order="big")
