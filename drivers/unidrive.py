"""Driver of the Control Techniques Unidrive SP over Modbus (pymodbus 3.16, TCP or RTU).

The driver talks to an injected pymodbus-like *sync* client, so the same code runs
against the drive, the simulated drive's server, or an in-process fake. Motion runs as a
drive-resident profile (docs/hardware-design.md): ``load_profile`` writes Pr 20.21–20.27
in one request, ``start`` raises RUN FWD in the control word, and ``poll`` reads the
status block Pr 20.31–20.38 while writing the control word with the watchdog bit
toggled — one FC 23 transaction, so polling costs one round trip even over RTU.

pymodbus returns error replies instead of raising them; they become exceptions here::

    Exception
     └── DriveError                                   anything the drive driver raises
          ├── DriveConnectionError (+ConnectionError)  cannot connect / link lost
          ├── DriveTimeoutError (+TimeoutError)        no reply after all retries
          ├── DriveReplyError                          the drive answered "exception N"
          │    ├── DriveAddressError (+LookupError)    exception 2: unknown parameter,
          │    │                                       read-only, or more than 16 registers
          │    └── DriveValueError (+ValueError)       exception 3: value not accepted
          ├── DriveTrippedError                        the drive is tripped (trip_code)
          ├── DriveProfileError (+ValueError)          the drive program refused a profile
          └── DriveClosedError (+ClosedError)          used after close()

The control word, and with it the watchdog of bit 14, counts only while Pr 6.43 = 1
(HARDWARE.md): ``enable`` sets it, ``stand_down`` (the end of an orderly run, and
``close``) writes the disabled word, then Pr 6.43 = 0, so the drive stays disabled and
healthy instead of tripping on the watchdog once polls stop.

``LimitError`` (drivers.limits) is raised before anything is written when a profile
breaks labstand's limits.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from urllib.parse import parse_qs, urlsplit

from pymodbus.client import ModbusSerialClient, ModbusTcpClient
from pymodbus.exceptions import ConnectionException, ModbusIOException
from pymodbus.pdu import ModbusPDU

from drivers import unidrive_registers as pr
from drivers.interfaces import DriveInterface, DriveState
from drivers.limits import DriveLimits
from drivers.signals import DriveProfile, SignalSpec, plan_motion
from drivers.unidrive_profile import (
    ProfileState,
    RejectReason,
    decode_profile,
    encode_home,
    encode_profile,
)
from drivers.unidrive_registers import ControlBit, Register
from drivers.unidrive_wire import (
    DriveAddressError,
    DriveClosedError,
    DriveConnectionError,
    DriveError,
    DriveProfileError,
    DriveReplyError,
    DriveTimeoutError,
    DriveTrippedError,
    DriveValueError,
    ModbusClient,
    decode_registers,
    encode_registers,
    exception_text,
)

log = logging.getLogger(__name__)

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
    "UnidriveSP",
    "open_unidrive",
]


def _what(regs: Sequence[Register]) -> str:
    if len(regs) == 1:
        return f"{regs[0].label} at address {regs[0].address}"
    return f"{regs[0].label} … {regs[-1].label} at address {regs[0].address}"


class UnidriveSP(DriveInterface):
    """The stand's drive converter.

    Parameters
    ----------
    client
        A pymodbus-like sync client (``ModbusTcpClient``, ``ModbusSerialClient`` or a
        fake); the driver closes it. Build real ones with ``open_unidrive``.
    limits
        Labstand's limits; profiles are planned against them and refused before anything
        moves. ``check_limits()`` compares them with the drive's own (before ``enable``).
    device_id
        Modbus unit id (Pr 11.23 for RTU).
    retries
        Extra attempts after a time-out or a lost link; exception replies are not retried.
    """

    def __init__(
        self,
        client: ModbusClient,
        limits: DriveLimits,
        *,
        device_id: int = 1,
        retries: int = 2,
        name: str = "Unidrive SP",
    ) -> None:
        self._client = client
        self._limits = limits
        self.device_id = device_id
        self.retries = retries
        self.name = name
        self._cw = ControlBit.AUTO.mask  # the control word as last written
        if not client.connect():
            # the client's repr is pymodbus's, not the user's words: the name holds the address
            raise DriveConnectionError(f"{name}: cannot connect (no answer at that address)")

    def _check_open(self) -> None:
        if self._closed:
            raise DriveClosedError(f"{self.name}: driver is closed")

    @property
    def limits(self) -> DriveLimits:
        """Labstand's limits for this drive."""
        return self._limits

    # ---- transactions ----------------------------------------------------------------
    def _transact(
        self, regs: Sequence[Register], call: Callable[[], ModbusPDU], words: int | None = None
    ) -> ModbusPDU:
        """``call`` with retries, its exception replies raised as ours.

        A read reply with another number of registers than ``words`` is garbled (seen over
        RTU: an empty reply) and counts as no reply.
        """
        what = _what(regs)
        last: Exception | None = None
        for attempt in range(self.retries + 1):
            try:
                reply = call()
            except ModbusIOException as err:
                last = err
                log.warning("%s: %s: no reply (attempt %d)", self.name, what, attempt + 1)
                continue
            except (ConnectionException, OSError) as err:
                # pymodbus raises a reset socket's OSError as it comes (a stand killed
                # mid-run): the link is lost all the same.
                last = err
                log.warning("%s: %s: link lost (attempt %d)", self.name, what, attempt + 1)
                self._client.close()
                if not self._client.connect():
                    continue
                continue
            if reply.isError():
                code = int(reply.exception_code)
                text = exception_text(code)
                msg = f"{self.name}: {what}: drive replied exception {code} ({text})"
                if code == 2:
                    raise DriveAddressError(msg, code)
                if code == 3:
                    raise DriveValueError(msg, code)
                raise DriveReplyError(msg, code)
            got = len(getattr(reply, "registers", None) or [])
            if words is not None and got != words:
                last = ModbusIOException(f"{got} registers in the reply, {words} asked")
                log.warning("%s: %s: garbled reply (attempt %d)", self.name, what, attempt + 1)
                continue
            return reply
        if isinstance(last, (ConnectionException, OSError)):
            raise DriveConnectionError(f"{self.name}: {what}: {last}") from last
        raise DriveTimeoutError(
            f"{self.name}: {what}: no reply after {self.retries + 1} attempts"
        ) from last

    def read_raw(self, regs: Sequence[Register]) -> list[int]:
        """Raw values of consecutive parameters of one width, in one request."""
        width, count = regs[0].width, sum(r.count for r in regs)
        reply = self._transact(
            regs,
            lambda: self._client.read_holding_registers(
                regs[0].address, count=count, device_id=self.device_id
            ),
            count,
        )
        return decode_registers(reply.registers, width)

    def write_raw(self, regs: Sequence[Register], raws: Sequence[int]) -> None:
        """Write raw values of consecutive parameters of one width, in one request."""
        words = encode_registers(raws, regs[0].width)
        self._transact(
            regs,
            lambda: self._client.write_registers(regs[0].address, words, device_id=self.device_id),
        )

    def read(self, reg: Register) -> float:
        """One parameter, scaled to its unit."""
        return reg.to_value(self.read_raw([reg])[0])

    def write(self, reg: Register, value: float) -> None:
        """Write one parameter given in its unit."""
        self.write_raw([reg], [reg.to_raw(value)])

    def _write_control(self, word: int) -> None:
        self.write_raw([pr.CONTROL_WORD], [word])
        self._cw = word

    # ---- DriveInterface --------------------------------------------------------------
    def _poll(self) -> DriveState:
        word = self._cw ^ ControlBit.WATCHDOG.mask
        words = encode_registers([word], 16)
        block = pr.STATUS_BLOCK
        reply = self._transact(
            block,
            lambda: self._client.readwrite_registers(
                read_address=block[0].address,
                read_count=2 * len(block),
                write_address=pr.CONTROL_WORD.address,
                values=words,
                device_id=self.device_id,
            ),
            2 * len(block),
        )
        self._cw = word
        raw = decode_registers(reply.registers, 32)
        pos, vel, ref, ptime, state, status, trip, clock = raw
        return DriveState(
            t_host_s=time.monotonic(),
            drive_clock_s=pr.DRIVE_CLOCK.to_value(clock),
            position_m=pr.POSITION.to_value(pos),
            velocity_m_s=pr.VELOCITY.to_value(vel),
            reference_m=pr.REFERENCE.to_value(ref),
            profile_time_s=pr.PROFILE_TIME.to_value(ptime),
            profile_state=ProfileState(state),
            status_word=status & 0xFFFF,
            trip_code=trip,
        )

    def _kick_watchdog(self) -> None:
        self._write_control(self._cw ^ ControlBit.WATCHDOG.mask)

    def _enable(self) -> None:
        trip = int(self.read_raw([pr.TRIP_CODE])[0])
        if trip:
            raise DriveTrippedError(f"{self.name}: tripped (trip {trip}); reset first", trip)
        self.write_raw([pr.CONTROL_WORD_ENABLE], [1])
        base = (self._cw & ControlBit.WATCHDOG.mask) | ControlBit.AUTO.mask
        self._write_control(base | ControlBit.ENABLE.mask)
        self._kick_watchdog()  # a 0 → 1 or 1 → 0 edge; the next poll completes a pair
        log.info("%s: enabled", self.name)

    def _disable(self) -> None:
        self._write_control((self._cw & ControlBit.WATCHDOG.mask) | ControlBit.AUTO.mask)
        log.info("%s: disabled", self.name)

    def _stand_down(self) -> None:
        # after _disable: the word is 128 (AUTO, output off); clearing Pr 6.43 takes the
        # control word out of force, its watchdog with it [HARDWARE.md: the word is active
        # only with Pr 6.43 = 1; that the real drive then forgets bit 14 is unconfirmed]
        self.write_raw([pr.CONTROL_WORD_ENABLE], [0])

    def _read_limits(self) -> DriveLimits:
        """The limits commissioned on the drive (Pr 20.28–20.30)."""
        amp, speed, accel = (
            reg.to_value(raw)
            for reg, raw in zip(pr.LIMIT_BLOCK, self.read_raw(pr.LIMIT_BLOCK), strict=True)
        )
        return DriveLimits(amp, speed, accel)

    def _load_profile(self, spec: SignalSpec) -> DriveProfile:
        plan_motion(spec, self._limits)  # refuse before anything is written
        raws = encode_profile(spec)
        profile = plan_motion(decode_profile(raws), self._limits)  # what the drive runs
        self._arm(raws)
        return profile

    def _arm(self, raws: list[int]) -> None:
        if self._cw & ControlBit.RUN_FWD.mask:
            self._write_control(self._cw & ~ControlBit.RUN_FWD.mask)
        self.write_raw(pr.PROFILE_BLOCK, raws)
        state, _status, _trip, _clock, reason = self.read_raw(
            (pr.PROFILE_STATE, pr.STATUS_MIRROR, pr.TRIP_MIRROR, pr.DRIVE_CLOCK, pr.REJECT_REASON)
        )
        if ProfileState(state) is not ProfileState.ARMED:
            why = RejectReason(reason)
            raise DriveProfileError(
                f"{self.name}: the drive program refused the profile "
                f"({pr.REJECT_REASON.label} = {reason}: {why.name.lower().replace('_', ' ')})",
                why,
            )

    def _start(self) -> None:
        if self._cw & ControlBit.RUN_FWD.mask:
            self._write_control(self._cw & ~ControlBit.RUN_FWD.mask)
        self._write_control(self._cw | ControlBit.RUN_FWD.mask)

    def _stop(self) -> None:
        self._write_control(self._cw & ~ControlBit.RUN_FWD.mask)

    def _home(self) -> None:
        self._arm(encode_home())
        self._start()

    def _reset_trip(self) -> None:
        self.write_raw([pr.USER_TRIP], [pr.USER_TRIP_RESET])
        self._cw = ControlBit.AUTO.mask | (self._cw & ControlBit.WATCHDOG.mask)
        log.info("%s: trip reset", self.name)

    def _close(self) -> None:
        try:
            self._disable()
            self._stand_down()
        except DriveError as err:
            log.warning("%s: could not disable (and stand down) on close: %s", self.name, err)
        finally:
            self._client.close()


def open_unidrive(
    url: str,
    limits: DriveLimits,
    *,
    timeout_s: float = 0.25,
    retries: int = 2,
    device_id: int = 1,
) -> UnidriveSP:
    """Connect to a drive by URL.

    ``tcp://HOST:PORT`` (Modbus TCP, port 502 by default) or ``rtu:///dev/ttyUSB0`` with
    optional ``?baudrate=115200&stopbits=2&parity=N`` (8 data bits; the Unidrive's
    serial frame is 8N2 [unconfirmed]).

    Parameters
    ----------
    url
        Where the drive is.
    limits
        Labstand's limits (see ``UnidriveSP``).
    timeout_s
        Reply time-out per attempt, s (the drive answers within 100 ms [manual]).
    retries
        Extra attempts after a time-out.
    device_id
        Modbus unit id (Pr 11.23).
    """
    parts = urlsplit(url)
    client: ModbusTcpClient | ModbusSerialClient
    if parts.scheme == "tcp":
        host, port = parts.hostname or "127.0.0.1", parts.port or 502
        client = ModbusTcpClient(host, port=port, timeout=timeout_s, retries=0)
    elif parts.scheme == "rtu":
        query = {k: v[-1] for k, v in parse_qs(parts.query).items()}
        client = ModbusSerialClient(
            parts.path,
            baudrate=int(query.get("baudrate", 115200)),
            bytesize=8,
            parity=query.get("parity", "N"),
            stopbits=int(query.get("stopbits", 2)),
            timeout=timeout_s,
            retries=0,
        )
    else:
        raise ValueError(f"drive URL must start with tcp:// or rtu://, got {url!r}")
    return UnidriveSP(
        client, limits, device_id=device_id, retries=retries, name=f"Unidrive SP {url}"
    )
