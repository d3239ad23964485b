"""The Unidrive SP parameter table: every Modbus address labstand uses, in one place.

A parameter ``Pr menu.param`` has the 0-based 16-bit holding-register address
``menu*100 + param - 1``; its 32-bit address sets bit 14 (``0x4000 | address``) and spans
two registers, high word first (HARDWARE.md, [manual]). All drive parameters are signed.

Menus 18–20 are application parameters, free for a drive-resident program. Labstand's
drive program (docs/hardware-design.md) uses the 32-bit parameters of menu 20:

* Pr 20.21–20.27: the motion profile labstand writes (one request, 14 registers);
* Pr 20.28–20.30: the limits commissioned on the drive (read-only for labstand);
* Pr 20.31–20.38: the status block labstand polls (one request, 16 registers);
* Pr 20.39: why the program refused the last profile.

``scale`` converts a raw parameter value to ``unit``: ``value = raw * scale``. Scalings
marked [unconfirmed] in HARDWARE.md are the drive's defaults as we believe them to be.

This table is pinned by tests/drivers/test_unidrive_registers.py against HARDWARE.md:
the driver and the simulated drive share it, so a wrong entry here would otherwise make
both agree with each other forever.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum, StrEnum

__all__ = [
    "ADDRESS_32BIT",
    "LIMIT_BLOCK",
    "MAX_REGISTERS",
    "PROFILE_BLOCK",
    "REGISTERS",
    "STATUS_BLOCK",
    "USER_TRIP_RANGE",
    "USER_TRIP_RESET",
    "Access",
    "ControlBit",
    "Register",
    "StatusBit",
    "TripCode",
    "by_address",
    "by_parameter",
]

#: Bit 14 of a protocol address selects 32-bit access.
ADDRESS_32BIT = 0x4000
#: The drive answers at most this many registers per request (more → exception 2).
MAX_REGISTERS = 16


class Access(StrEnum):
    """Who may write a parameter over Modbus."""

    RO = "ro"
    RW = "rw"


@dataclass(frozen=True)
class Register:
    """One drive parameter.

    Attributes
    ----------
    menu, param
        ``Pr menu.param``.
    width
        16 or 32 (bits); 32-bit parameters are read and written as two registers.
    scale
        Raw value × scale = value in ``unit``.
    unit
        Unit after scaling ("" for codes and bit fields).
    access
        Read-only or read-write over Modbus.
    name
        What the parameter means; used in error messages.
    """

    menu: int
    param: int
    width: int
    scale: float
    unit: str
    access: Access
    name: str

    def __post_init__(self) -> None:
        if self.width not in {16, 32}:
            raise ValueError(f"Pr {self.menu}.{self.param:02d}: width must be 16 or 32")
        if not (0 <= self.menu <= 99 and 0 <= self.param <= 99):
            raise ValueError(f"Pr {self.menu}.{self.param:02d}: menu and param are 0..99")

    @property
    def address16(self) -> int:
        """The 16-bit protocol address, 0-based: menu*100 + param − 1."""
        return self.menu * 100 + self.param - 1

    @property
    def address(self) -> int:
        """The address labstand uses: 32-bit parameters with bit 14 set."""
        return self.address16 | ADDRESS_32BIT if self.width == 32 else self.address16

    @property
    def count(self) -> int:
        """Registers one value occupies at ``address``."""
        return self.width // 16

    @property
    def label(self) -> str:
        """``Pr 10.20 (trip code)``: how messages name the parameter."""
        return f"Pr {self.menu}.{self.param:02d} ({self.name})"

    def to_value(self, raw: int) -> float:
        """Raw parameter value → value in ``unit`` (decimal scales divide, so 200000 µ → 0.2)."""
        per_unit = 1.0 / self.scale
        if per_unit > 1 and abs(per_unit - round(per_unit)) < 1e-9 * per_unit:
            return raw / round(per_unit)
        return raw * self.scale

    def to_raw(self, value: float) -> int:
        """Value in ``unit`` → nearest raw parameter value."""
        return round(value / self.scale)


RO, RW = Access.RO, Access.RW

# ---- drive parameters [manual] (scaling of speeds [unconfirmed]) ----------------------
REFERENCE_SELECTOR = Register(1, 14, 16, 1, "", RW, "reference selector")
SPEED_REFERENCE = Register(1, 21, 32, 0.1, "rpm", RW, "digital speed reference 1")
SPEED_FEEDBACK = Register(3, 2, 32, 0.1, "rpm", RO, "speed feedback")
ENCODER_TURNS = Register(3, 28, 16, 1, "rev", RO, "encoder revolution count")
ENCODER_POSITION = Register(3, 29, 16, 1 / 65536, "rev", RO, "encoder position")
ENCODER_FINE = Register(3, 30, 16, 1 / 65536**2, "rev", RO, "encoder fine position")
START_STOP_LOGIC = Register(6, 4, 16, 1, "", RW, "start/stop logic select")
DRIVE_ENABLE = Register(6, 15, 16, 1, "", RW, "drive enable")
CONTROL_WORD = Register(6, 42, 16, 1, "", RW, "control word")
CONTROL_WORD_ENABLE = Register(6, 43, 16, 1, "", RW, "control word enable")
DRIVE_HEALTHY = Register(10, 1, 16, 1, "", RO, "drive healthy")
TRIP_CODE = Register(10, 20, 16, 1, "", RO, "latest trip code")
USER_TRIP = Register(10, 38, 16, 1, "", RW, "user trip")
STATUS_WORD = Register(10, 40, 16, 1, "", RO, "status word")
SERIAL_ADDRESS = Register(11, 23, 16, 1, "", RW, "serial address")
SERIAL_MODE = Register(11, 24, 16, 1, "", RW, "serial mode")
SERIAL_BAUD = Register(11, 25, 16, 1, "", RW, "serial baud rate")
SERIAL_DELAY = Register(11, 26, 16, 1e-3, "s", RW, "serial transmit delay")

# ---- labstand's drive program (application parameters, docs/hardware-design.md) ------
PROFILE_SHAPE = Register(20, 21, 32, 1, "", RW, "profile shape")
PROFILE_AMPLITUDE = Register(20, 22, 32, 1e-6, "m", RW, "profile amplitude")
PROFILE_FREQUENCY = Register(20, 23, 32, 1e-6, "Hz", RW, "profile frequency")
PROFILE_CYCLES = Register(20, 24, 32, 1, "", RW, "profile cycles")
PROFILE_RAMP = Register(20, 25, 32, 1e-6, "", RW, "profile ramp fraction")
PROFILE_DWELL_START = Register(20, 26, 32, 1e-6, "s", RW, "profile start dwell")
PROFILE_DWELL_END = Register(20, 27, 32, 1e-6, "s", RW, "profile end dwell")
LIMIT_AMPLITUDE = Register(20, 28, 32, 1e-6, "m", RO, "amplitude limit")
LIMIT_SPEED = Register(20, 29, 32, 1e-6, "m/s", RO, "speed limit")
LIMIT_ACCEL = Register(20, 30, 32, 1e-6, "m/s²", RO, "acceleration limit")
POSITION = Register(20, 31, 32, 1e-6, "m", RO, "drive position")
VELOCITY = Register(20, 32, 32, 1e-6, "m/s", RO, "drive velocity")
REFERENCE = Register(20, 33, 32, 1e-6, "m", RO, "position reference")
PROFILE_TIME = Register(20, 34, 32, 1e-5, "s", RO, "profile time")  # ≤ 5.9 h
PROFILE_STATE = Register(20, 35, 32, 1, "", RO, "profile state")
STATUS_MIRROR = Register(20, 36, 32, 1, "", RO, "status word copy")
TRIP_MIRROR = Register(20, 37, 32, 1, "", RO, "trip code copy")
DRIVE_CLOCK = Register(20, 38, 32, 1e-3, "s", RO, "drive clock")
REJECT_REASON = Register(20, 39, 32, 1, "", RO, "profile reject reason")

#: The whole table, in address order.
REGISTERS: tuple[Register, ...] = tuple(
    sorted(
        (v for v in dict(globals()).values() if isinstance(v, Register)),
        key=lambda r: r.address16,
    )
)
#: Profile parameters, written together in one request.
PROFILE_BLOCK = (
    PROFILE_SHAPE,
    PROFILE_AMPLITUDE,
    PROFILE_FREQUENCY,
    PROFILE_CYCLES,
    PROFILE_RAMP,
    PROFILE_DWELL_START,
    PROFILE_DWELL_END,
)
#: The status block labstand polls, read together in one request of 16 registers.
STATUS_BLOCK = (
    POSITION,
    VELOCITY,
    REFERENCE,
    PROFILE_TIME,
    PROFILE_STATE,
    STATUS_MIRROR,
    TRIP_MIRROR,
    DRIVE_CLOCK,
)
LIMIT_BLOCK = (LIMIT_AMPLITUDE, LIMIT_SPEED, LIMIT_ACCEL)

_BY_ADDRESS16 = {r.address16: r for r in REGISTERS}
if len(_BY_ADDRESS16) != len(REGISTERS):  # pragma: no cover - table sanity
    raise RuntimeError("two registers share an address")


def by_address(address: int) -> Register | None:
    """The parameter at a 16- or 32-bit protocol address, or None if there is none."""
    return _BY_ADDRESS16.get(address & ~ADDRESS_32BIT)


def by_parameter(menu: int, param: int) -> Register:
    """The parameter ``Pr menu.param``; KeyError if labstand does not know it."""
    reg = _BY_ADDRESS16.get(menu * 100 + param - 1)
    if reg is None or (reg.menu, reg.param) != (menu, param):
        raise KeyError(f"Pr {menu}.{param:02d} is not in the parameter table")
    return reg


class ControlBit(IntEnum):
    """Bits of the control word Pr 6.42 [manual; 12–13 unconfirmed]."""

    ENABLE = 0
    RUN_FWD = 1
    JOG_FWD = 2
    RUN_REV = 3
    FWD_REV = 4
    RUN = 5
    NOT_STOP = 6
    AUTO = 7
    REMOTE = 8
    JOG_REV = 9
    TRIP = 12
    RESET = 13
    WATCHDOG = 14

    @property
    def mask(self) -> int:
        """The bit as a mask."""
        return 1 << self.value


class StatusBit(IntEnum):
    """Bits of the status word Pr 10.40 (bit n = Pr 10.(n+1)) [manual]."""

    HEALTHY = 0
    ACTIVE = 1
    ZERO_SPEED = 2
    AT_SPEED = 5
    CURRENT_LIMIT = 8
    DIRECTION_COMMANDED = 12
    DIRECTION_RUNNING = 13
    MAINS_LOSS = 14

    @property
    def mask(self) -> int:
        """The bit as a mask."""
        return 1 << self.value


class TripCode(IntEnum):
    """Trip codes labstand tells apart (Pr 10.20)."""

    NONE = 0
    WATCHDOG = 30  # control-word watchdog not toggled within 1 s [HARDWARE.md]
    OVER_TRAVEL = 41  # user trip raised by labstand's drive program [our choice]
    CONTROL_WORD = 52  # trip requested with control-word bit 12 [unconfirmed]


#: Writing this to Pr 10.38 resets a tripped drive [manual]; 40..89 raise user trips.
USER_TRIP_RESET = 100
USER_TRIP_RANGE = range(40, 90)
