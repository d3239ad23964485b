"""The drive-resident motion profile: how a SignalSpec travels to the drive and back.

Labstand writes a profile as seven raw 32-bit parameters (Pr 20.21–20.27, see
``drivers.unidrive_registers.PROFILE_BLOCK``); the drive program decodes them, plans
``drivers.signals.plan_motion(spec, drive_limits)`` itself and executes it. Both sides
plan from the *decoded* spec, so the motion labstand expects and the one the drive runs
are the same to the last bit of the quantisation (1 µm, 1 µHz, 1 µs, 10⁻⁶).
"""

from __future__ import annotations

from enum import IntEnum

from drivers.signals import Shape, SignalSpec
from drivers.unidrive_registers import PROFILE_BLOCK

__all__ = [
    "ProfileState",
    "RejectReason",
    "ShapeCode",
    "decode_profile",
    "encode_home",
    "encode_profile",
]


class ShapeCode(IntEnum):
    """Pr 20.21: what the drive program runs on the next RUN FWD edge."""

    NONE = 0
    RECTANGULAR = 1
    TRAPEZOIDAL = 2
    QUASI_SINUSOIDAL = 3
    HOME = 4  # time-optimal move from wherever the drive stands back to x = 0


class ProfileState(IntEnum):
    """Pr 20.35: where the drive program is."""

    IDLE = 0  # nothing loaded
    ARMED = 1  # a valid profile is loaded; RUN FWD (0 → 1) starts it
    RUNNING = 2
    DONE = 3  # ran to its end; holding x = 0
    ABORTED = 4  # stopped early: RUN FWD cleared, disabled or tripped
    REJECTED = 5  # the last profile written was refused (reason in Pr 20.39)


class RejectReason(IntEnum):
    """Pr 20.39: why the drive program refused a profile."""

    NONE = 0
    BAD_SHAPE = 1  # unknown shape code
    BAD_VALUE = 2  # a value out of range (non-positive frequency, cycles < 1, ...)
    LIMITS = 3  # the motion breaks the drive's commissioned limits
    NOT_AT_HOME = 4  # a profile was started away from x = 0 (home first)
    BUSY = 5  # written while a profile was running


_SHAPE_TO_CODE = {
    Shape.RECTANGULAR: ShapeCode.RECTANGULAR,
    Shape.TRAPEZOIDAL: ShapeCode.TRAPEZOIDAL,
    Shape.QUASI_SINUSOIDAL: ShapeCode.QUASI_SINUSOIDAL,
}
_CODE_TO_SHAPE = {code: shape for shape, code in _SHAPE_TO_CODE.items()}
_INT32 = (-(2**31), 2**31 - 1)


def encode_profile(spec: SignalSpec) -> list[int]:
    """The raw values of Pr 20.21–20.27 for a signal.

    Raises
    ------
    ValueError
        A value does not fit its 32-bit parameter.
    """
    values = [
        float(_SHAPE_TO_CODE[spec.shape]),
        spec.amplitude_m,
        spec.frequency_hz,
        float(spec.cycles),
        spec.ramp_fraction,
        spec.dwell_start_s,
        spec.dwell_end_s,
    ]
    raws = [reg.to_raw(v) for reg, v in zip(PROFILE_BLOCK, values, strict=True)]
    for reg, raw in zip(PROFILE_BLOCK, raws, strict=True):
        if not _INT32[0] <= raw <= _INT32[1]:
            raise ValueError(f"{reg.label}: raw value {raw} does not fit 32 bits")
    return raws


def encode_home() -> list[int]:
    """The raw values of Pr 20.21–20.27 that load the home move."""
    return [int(ShapeCode.HOME)] + [0] * (len(PROFILE_BLOCK) - 1)


def decode_profile(raws: list[int]) -> SignalSpec:
    """The signal the drive program reads from Pr 20.21–20.27.

    Raises
    ------
    ValueError
        Unknown shape code (HOME and NONE are not signals) or a wrong number of values.
    """
    if len(raws) != len(PROFILE_BLOCK):
        raise ValueError(f"a profile has {len(PROFILE_BLOCK)} parameters, got {len(raws)}")
    try:
        shape = _CODE_TO_SHAPE[ShapeCode(raws[0])]
    except (ValueError, KeyError):
        raise ValueError(f"{PROFILE_BLOCK[0].label}: {raws[0]} is not a signal shape") from None
    amp, freq, cycles, ramp, dwell0, dwell1 = (
        reg.to_value(raw) for reg, raw in zip(PROFILE_BLOCK[1:], raws[1:], strict=True)
    )
    return SignalSpec(
        shape=shape,
        amplitude_m=amp,
        frequency_hz=freq,
        cycles=int(cycles),
        ramp_fraction=ramp,
        dwell_start_s=dwell0,
        dwell_end_s=dwell1,
    )
