"""The two small interfaces an acquisition session depends on.

``DriveInterface`` moves the stand; ``GaugeSource`` delivers the 2 kHz samples. A backend
(the real stand, the simulated stand over the same wire protocols, a fake in a unit test)
is picked by configuration; the session never names a concrete class.

Both follow one pattern (python-can's ``BusABC``): the public methods own the shared
work — the closed-state check, argument checks, logging — and a backend implements small
``_hooks``. Both are context managers and refuse work once closed.
"""

from __future__ import annotations

import logging
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Self

import numpy as np
from numpy.typing import NDArray

from drivers.closing import ClosesOnExit
from drivers.errors import ClosedError, DriveNotReadyError
from drivers.limits import DriveLimits, LimitError
from drivers.signals import DriveProfile, SignalSpec
from drivers.unidrive_profile import ProfileState
from drivers.unidrive_registers import StatusBit, TripCode

log = logging.getLogger(__name__)

__all__ = [
    "SAMPLE_DTYPE",
    "ClosedError",
    "DriveInterface",
    "DriveState",
    "GaugeSource",
    "GaugeStats",
]

#: One gauge sample as a GaugeSource hands it on (numpy structured array rows).
#: seq and t_device_us are unwrapped (never wrap); t_host_ns is time.monotonic_ns() when
#: the bytes were read (all samples of one read share it); flags are FrameFlag bits.
SAMPLE_DTYPE = np.dtype(
    [
        ("seq", "<i8"),
        ("t_device_us", "<i8"),
        ("t_host_ns", "<i8"),
        ("force_n", "<f8"),
        ("u_mm", "<f8"),
        ("x_mm", "<f8"),
        ("flags", "u1"),
    ]
)


#: What a trip found at pre-flight means. An orderly end stands the watchdog down, so a
#: watchdog trip means the controller died or lost the link while in control.
_TRIP_CAUSES = {
    int(TripCode.WATCHDOG): ": the controller stopped toggling it while in control — "
    "a killed labstand or a lost link",
    int(TripCode.OVER_TRAVEL): ": the axis ran beyond its stroke",
}


@dataclass(frozen=True)
class DriveState:
    """One poll of the drive (SI units).

    Attributes
    ----------
    t_host_s
        ``time.monotonic()`` when the reply arrived, s.
    drive_clock_s
        The drive's own clock (wraps after 24.8 days), s.
    position_m, velocity_m_s
        Drive position x (downward positive) and velocity.
    reference_m
        The position the drive program commands.
    profile_time_s
        Time since the profile started, s.
    profile_state
        Where the drive program is.
    status_word
        Pr 10.40 bits (StatusBit).
    trip_code
        Pr 10.20; 0 when not tripped.
    """

    t_host_s: float
    drive_clock_s: float
    position_m: float
    velocity_m_s: float
    reference_m: float
    profile_time_s: float
    profile_state: ProfileState
    status_word: int
    trip_code: int

    @property
    def healthy(self) -> bool:
        """Not tripped."""
        return bool(self.status_word & StatusBit.HEALTHY.mask) and self.trip_code == 0

    @property
    def active(self) -> bool:
        """The drive's output is active (enabled and controlling the motor)."""
        return bool(self.status_word & StatusBit.ACTIVE.mask)

    @property
    def tripped(self) -> bool:
        """The drive is tripped (trip_code names why)."""
        return self.trip_code != 0

    @property
    def trip_description(self) -> str:
        """``trip 30 (watchdog: why)``, or ``trip 45`` for a code without a name."""
        code, name = self.trip_code, self.trip_name
        if name == f"trip {code}":
            return name
        return f"trip {code} ({name}{_TRIP_CAUSES.get(code, '')})"

    @property
    def trip_name(self) -> str:
        """A readable name of the trip code."""
        try:
            return TripCode(self.trip_code).name.lower().replace("_", " ")
        except ValueError:
            return f"trip {self.trip_code}"


class _Device(ClosesOnExit, ABC):
    """What both interfaces share: closing, the closed-state check, the context manager.

    ``close`` is idempotent; ``_close`` does the work (a drive disables itself there).
    """

    _closed: bool = False
    name: str = "device"
    kind: str = "device"

    def _check_open(self) -> None:
        if self._closed:
            raise ClosedError(f"{self.name}: {self.kind} is closed")

    def close(self) -> None:
        """Release the device (a drive is disabled first if possible); idempotent."""
        if self._closed:
            return
        try:
            self._close()
        finally:
            self._closed = True

    @property
    def closed(self) -> bool:
        """True once closed."""
        return self._closed

    def __enter__(self) -> Self:
        self._check_open()
        return self

    @abstractmethod
    def _close(self) -> None: ...


class DriveInterface(_Device):
    """A linear drive that runs planned motion profiles.

    The drive trips by itself unless ``poll()`` (or ``kick_watchdog()``) is called at
    least every 0.5 s once ``enable()`` armed the watchdog, so a dead controller stops
    the stand. A controller that ends in order calls ``stand_down()`` (``close()`` does):
    the drive is disabled, then the watchdog is released, and the drive stays healthy for
    the next run. A trip is left only by a real fault: the drive's own, or a controller
    that died or lost the link.
    """

    name: str = "drive"
    kind: str = "driver"
    _limits_checked: bool = False

    @property
    @abstractmethod
    def limits(self) -> DriveLimits:
        """The limits profiles are planned and checked against."""

    def check_limits(self) -> DriveLimits:
        """The drive's own commissioned limits; LimitError if labstand's are looser.

        Part of every pre-flight: ``enable()`` is refused on a connection where this has
        not passed, so nothing moves under limits nobody compared with the drive's.
        """
        self._check_open()
        theirs = self._read_limits()
        mine = self.limits
        for what, own, drive, unit in (
            ("amplitude", mine.amplitude_max_m, theirs.amplitude_max_m, "m"),
            ("speed", mine.speed_max_m_s, theirs.speed_max_m_s, "m/s"),
            ("acceleration", mine.accel_max_m_s2, theirs.accel_max_m_s2, "m/s²"),
        ):
            if own > drive * (1 + 1e-6):
                raise LimitError(
                    f"{self.name}: labstand's {what} limit {own:g} {unit} exceeds the "
                    f"drive's commissioned {drive:g} {unit}"
                )
        self._limits_checked = True
        return theirs

    def poll(self) -> DriveState:
        """Read position, velocity, profile state, status and trip; toggles the watchdog."""
        self._check_open()
        return self._poll()

    def enable(self) -> None:
        """Enable the drive (control word ENABLE + AUTO); arms the watchdog.

        Raises
        ------
        DriveNotReadyError
            ``check_limits()`` has not passed on this connection (nothing written).
        """
        self._check_open()
        if not self._limits_checked:
            raise DriveNotReadyError(
                f"{self.name}: enable refused: the drive's limits were not checked "
                "(pre-flight: check_limits())"
            )
        self._enable()

    def disable(self) -> None:
        """Disable the drive at once (the motor coasts): the emergency stop."""
        self._check_open()
        self._disable()

    def stand_down(self) -> None:
        """Disable the drive, then release its watchdog: it stays disabled and healthy.

        The end of every orderly run (and ``close()``). A later ``enable()`` arms the
        watchdog again. A tripped drive stays tripped (``reset_trip`` clears it).
        """
        self._check_open()
        self._disable()
        self._stand_down()
        log.info("%s: disabled, watchdog stood down", self.name)

    def load_profile(self, spec: SignalSpec) -> DriveProfile:
        """Plan a motion within the limits and load it into the drive (nothing moves).

        Returns the motion the drive will execute.
        """
        self._check_open()
        return self._load_profile(spec)

    def start(self) -> None:
        """Start the loaded profile (or home move)."""
        self._check_open()
        self._start()

    def stop(self) -> None:
        """Controlled stop: decelerate to rest within the limits, stay enabled."""
        self._check_open()
        self._stop()

    def home(self) -> None:
        """Load and start the move back to x = 0."""
        self._check_open()
        self._home()

    def reset_trip(self) -> None:
        """Reset a tripped drive (it comes back disabled)."""
        self._check_open()
        self._reset_trip()

    def kick_watchdog(self) -> None:
        """Toggle the watchdog without polling."""
        self._check_open()
        self._kick_watchdog()

    @abstractmethod
    def _read_limits(self) -> DriveLimits: ...
    @abstractmethod
    def _poll(self) -> DriveState: ...
    @abstractmethod
    def _enable(self) -> None: ...
    @abstractmethod
    def _disable(self) -> None: ...
    @abstractmethod
    def _load_profile(self, spec: SignalSpec) -> DriveProfile: ...
    @abstractmethod
    def _start(self) -> None: ...
    @abstractmethod
    def _stop(self) -> None: ...
    @abstractmethod
    def _home(self) -> None: ...
    @abstractmethod
    def _reset_trip(self) -> None: ...
    @abstractmethod
    def _kick_watchdog(self) -> None: ...
    @abstractmethod
    def _stand_down(self) -> None: ...


@dataclass(frozen=True)
class GaugeStats:
    """Counters of a gauge source since it started.

    Attributes
    ----------
    frames
        Valid frames received.
    lost
        Frames missing from the device's sequence (gaps).
    corrupt
        Resynchronisations after garbage or corrupted frames.
    skipped_bytes
        Bytes discarded while resynchronising.
    overruns
        Frames the device flagged as following its own buffer overrun.
    dropped_blocks
        Blocks discarded because the consumer did not take them (queue full).
    bytes_read
        Bytes read from the port.
    """

    frames: int = 0
    lost: int = 0
    corrupt: int = 0
    skipped_bytes: int = 0
    overruns: int = 0
    dropped_blocks: int = 0
    bytes_read: int = 0


class GaugeSource(_Device):
    """The 2 kHz force / weight-position / drive-position samples, in blocks."""

    name: str = "gauges"
    kind: str = "gauge source"
    rate_hz: float = 2000.0

    def read_block(self, timeout_s: float = 0.1) -> NDArray[np.void] | None:
        """The next block of samples (SAMPLE_DTYPE), or None if none came within timeout_s.

        Raises
        ------
        GaugeError
            The source failed (port vanished, reader died); raised once, then closed.
        """
        self._check_open()
        if timeout_s < 0:
            raise ValueError(f"timeout must be ≥ 0 s, got {timeout_s:g} s")
        return self._read_block(timeout_s)

    def stats(self) -> GaugeStats:
        """Counters so far (thread-safe snapshot)."""
        return self._stats()

    @abstractmethod
    def _read_block(self, timeout_s: float) -> NDArray[np.void] | None: ...
    @abstractmethod
    def _stats(self) -> GaugeStats: ...
