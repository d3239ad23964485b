"""Scheduled faults of the simulated stand: how tests make the hardware fail on cue.

``labstand stand-sim --fault KIND@T[:VALUE]`` schedules a fault ``T`` simulated seconds
after the simulated drive starts its first profile (the RUN FWD edge that starts it), so
a test hits the same phase of the motion however long labstand's pre-flight took:

=================  =====================================================================
kind               what happens (VALUE)
=================  =====================================================================
``trip``           the drive trips as if Pr 10.38 were written (user trip code, 45)
``gauges-silent``  the gauge front end stops sending frames; the drive runs on
``garbage``        random bytes are sent between two frames (how many, 200)
``modbus-mute``    the drive stops answering Modbus requests (for how long, s; forever)
=================  =====================================================================

A trip can also come from outside, over Modbus (write 40–89 to Pr 10.38); the others
have no wire-level equivalent, hence this hook.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

__all__ = ["Fault", "FaultKind", "FaultPlan", "parse_fault"]


class FaultKind(StrEnum):
    """What fails."""

    TRIP = "trip"
    GAUGES_SILENT = "gauges-silent"
    GARBAGE = "garbage"
    MODBUS_MUTE = "modbus-mute"


_DEFAULT_VALUE = {
    FaultKind.TRIP: 45.0,
    FaultKind.GAUGES_SILENT: math.inf,
    FaultKind.GARBAGE: 200.0,
    FaultKind.MODBUS_MUTE: math.inf,
}


@dataclass(frozen=True)
class Fault:
    """One scheduled fault.

    Attributes
    ----------
    kind
        What fails.
    after_s
        Simulated seconds after the drive starts its first profile, s.
    value
        Trip code, garbage bytes, or mute duration in s (see the module docstring).
    """

    kind: FaultKind
    after_s: float
    value: float

    def __str__(self) -> str:
        return f"{self.kind}@{self.after_s:g}:{self.value:g}"


def parse_fault(text: str) -> Fault:
    """``KIND@T[:VALUE]`` → a Fault.

    Raises
    ------
    ValueError
        Unknown kind, or a time or value that is not a number in range.
    """
    kind_text, at, rest = text.partition("@")
    try:
        kind = FaultKind(kind_text.strip())
    except ValueError:
        known = ", ".join(k.value for k in FaultKind)
        raise ValueError(f"--fault {text!r}: unknown kind; one of {known}") from None
    time_text, _, value_text = rest.partition(":")
    try:
        after_s = float(time_text) if at else 0.0
        value = float(value_text) if value_text else _DEFAULT_VALUE[kind]
    except ValueError:
        raise ValueError(f"--fault {text!r}: expected KIND@SECONDS[:VALUE]") from None
    if not (math.isfinite(after_s) and after_s >= 0):
        raise ValueError(f"--fault {text!r}: the time must be ≥ 0 s")
    if not value > 0 or (kind is FaultKind.TRIP and int(value) not in range(40, 90)):
        raise ValueError(f"--fault {text!r}: value out of range")
    return Fault(kind, after_s, value)


class FaultPlan:
    """The faults still to come, released as simulated time passes."""

    def __init__(self, faults: tuple[Fault, ...] = ()) -> None:
        self._pending = sorted(faults, key=lambda f: f.after_s)
        self.start_s: float | None = None  # drive time when the first profile started

    def due(self, t_s: float, profile_running: bool) -> list[Fault]:
        """Faults whose time has come at drive time ``t_s``, s."""
        if not self._pending:
            return []
        if self.start_s is None:
            if not profile_running:
                return []
            self.start_s = t_s
        now = [f for f in self._pending if t_s - self.start_s >= f.after_s]
        self._pending = self._pending[len(now) :]
        return now
