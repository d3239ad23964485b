"""The simulated drive on the wire: Modbus requests → SimulatedDrive, and the servers.

pymodbus 3.16 serves a ``SimDevice`` whose ``action`` coroutine sees every request before
the register block is answered; here the block is only a scratch buffer that the action
fills from (or empties into) the drive, so every read returns the drive's state at that
moment and every write acts on it. ``id=0`` answers any unit id. pymodbus itself allows
125 registers per request; the real drive's 16 are enforced here.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from functools import partial

from pymodbus import FramerType
from pymodbus.constants import ExcCodes
from pymodbus.server import ModbusSerialServer, ModbusTcpServer
from pymodbus.simulator import DataType, SimData, SimDevice

from drivers import unidrive_registers as pr
from drivers.unidrive_registers import ADDRESS_32BIT, MAX_REGISTERS, Register
from sim.hardware.drive import SimulatedDrive

log = logging.getLogger(__name__)

__all__ = ["make_device", "read_request", "start_rtu_server", "start_tcp_server", "write_request"]

_SPAN = ADDRESS_32BIT + 100 * 21  # addresses 0 … 32-bit Pr 20.99
_FC_WRITE_SINGLE = 6


def _signed(value: int, bits: int) -> int:
    value &= (1 << bits) - 1
    return value - (1 << bits) if value >> (bits - 1) else value


def _params(address: int, count: int, write: bool) -> list[Register] | ExcCodes:
    """The parameters a request covers, or the exception the drive answers."""
    if not 1 <= count <= MAX_REGISTERS:
        return ExcCodes.ILLEGAL_ADDRESS
    wide = bool(address & ADDRESS_32BIT)
    if wide and count % 2:
        return ExcCodes.ILLEGAL_ADDRESS
    base = address & ~ADDRESS_32BIT
    regs = []
    for i in range(count // 2 if wide else count):
        reg = pr.by_address(base + i)
        if reg is None or (write and reg.access is not pr.Access.RW):
            return ExcCodes.ILLEGAL_ADDRESS
        regs.append(reg)
    return regs


def read_request(drive: SimulatedDrive, address: int, count: int) -> list[int] | ExcCodes:
    """The register words a read of ``count`` registers at ``address`` returns."""
    regs = _params(address, count, write=False)
    if isinstance(regs, ExcCodes):
        return regs
    words: list[int] = []
    for reg in regs:
        raw = drive.value(reg) & 0xFFFFFFFF
        if address & ADDRESS_32BIT:
            words += [raw >> 16, raw & 0xFFFF]
        else:
            words.append(raw & 0xFFFF)  # a 32-bit parameter gives its low word
    return words


def write_request(drive: SimulatedDrive, address: int, words: list[int]) -> ExcCodes | None:
    """Apply a write of ``words`` at ``address``; returns the exception, if any."""
    regs = _params(address, len(words), write=True)
    if isinstance(regs, ExcCodes):
        return regs
    wide = bool(address & ADDRESS_32BIT)
    for i, reg in enumerate(regs):
        word = (words[2 * i] << 16) | words[2 * i + 1] if wide else words[i]
        raw = _signed(word, 32 if wide else 16)
        drive.set_value(reg, raw)
    if any(reg in pr.PROFILE_BLOCK for reg in regs):
        drive.arm_profile()
    return None


async def _action(
    drive: SimulatedDrive,
    sync: Callable[[], None],
    muted: Callable[[], bool],
    function_code: int,
    start_address: int,
    address: int,
    count: int,
    registers: list[int],
    set_values: list[int] | list[bool] | None,
) -> ExcCodes | None:
    while muted():  # fault injection: the drive stops answering (the request waits)
        await asyncio.sleep(0.01)
    sync()
    if set_values is not None:
        return write_request(drive, address, [int(v) for v in set_values])
    if function_code == _FC_WRITE_SINGLE:
        return None  # the read-back of a single write: echo what was written
    words = read_request(drive, address, count)
    if isinstance(words, ExcCodes):
        return words
    offset = address - start_address
    registers[offset : offset + count] = words
    return None


def make_device(
    drive: SimulatedDrive,
    sync: Callable[[], None],
    muted: Callable[[], bool] = lambda: False,
) -> SimDevice:
    """A pymodbus SimDevice answering any unit id with the simulated drive.

    Parameters
    ----------
    drive
        The simulated drive that answers.
    sync
        Called before every request: advances the simulated stand to the present.
    muted
        While it returns True, requests get no answer (a drive that stopped talking).
    """
    return SimDevice(
        id=0,
        action=partial(_action, drive, sync, muted),
        simdata=[SimData(address=0, count=_SPAN, values=0, datatype=DataType.REGISTERS)],
    )


async def start_tcp_server(
    device: SimDevice, host: str = "127.0.0.1", port: int = 0
) -> tuple[ModbusTcpServer, int]:
    """Serve Modbus TCP on host:port (0 = any free port); returns the server and its port."""
    if host not in {"127.0.0.1", "localhost"}:
        raise ValueError(f"the simulated drive serves on loopback only, not {host!r}")
    server = ModbusTcpServer(device, address=(host, port))
    try:
        await server.serve_forever(background=True)
    except RuntimeError as err:  # pymodbus's way of saying "bind failed"
        await server.shutdown()  # type: ignore[no-untyped-call]
        raise OSError(f"cannot listen on {host}:{port} (address in use?)") from err
    sockets = getattr(server.transport, "sockets", None)
    if not sockets:
        await server.shutdown()  # type: ignore[no-untyped-call]
        raise OSError(f"cannot listen on {host}:{port}")
    bound = int(sockets[0].getsockname()[1])
    log.info("simulated drive: Modbus TCP on %s:%d", host, bound)
    return server, bound


async def start_rtu_server(
    device: SimDevice, port: str, baudrate: int = 115200
) -> ModbusSerialServer:
    """Serve Modbus RTU (8N2) on a serial port path, e.g. one end of a pty pair."""
    server = ModbusSerialServer(
        device,
        framer=FramerType.RTU,
        port=port,
        baudrate=baudrate,
        bytesize=8,
        parity="N",
        stopbits=2,
        timeout=0.1,
    )
    try:
        await server.serve_forever(background=True)
    except RuntimeError as err:
        await server.shutdown()  # type: ignore[no-untyped-call]
        raise OSError(f"cannot open {port} for Modbus RTU") from err
    if not server.transport:
        await server.shutdown()  # type: ignore[no-untyped-call]
        raise OSError(f"cannot open {port} for Modbus RTU")
    log.info("simulated drive: Modbus RTU on %s", port)
    return server
