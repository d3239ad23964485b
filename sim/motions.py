"""The motions a plan chooses among: a coarse grid of the drive's signals, and their length.

The search judges each motion on a short version (``MOTION_S`` of motion: the
separation is an RMS over the motion's cycles, so more of them would not raise it); the
test it plans runs longer (``PLAN_S``), because the diagnosis judges a candidate on the
*held-out* cycles of each recording (every other cycle), and a 3 s motion at 1 Hz gives
it one.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from drivers.limits import DriveLimits, LimitError
from drivers.signals import Shape, SignalSpec, plan_motion

__all__ = ["MOTION_S", "PLAN_S", "Candidate", "lengthened", "motion_grid", "padded"]

FloatArray = NDArray[np.float64]

#: The grid [estimate]: strokes, rates and ramps spanning the drive's range coarsely.
AMPLITUDES_MM = (10.0, 25.0, 45.0, 70.0, 90.0)
FREQUENCIES_HZ = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0)
RAMP_FRACTIONS = (0.1, 0.25, 0.4)
#: Each motion lasts about this long (cycles = rate × this, at least 2), s: long enough
#: for the weight's response to settle into its cycle, short enough to keep the search
#: cheap; the separation is an RMS, so more cycles would not raise it.
MOTION_S = 3.0
#: The planned test's motion, s (cycles = rate × this, at least ``PLAN_CYCLES``): the
#: diagnosis' evidence is its held-out cycles, every other one; a 3 s test at 1 Hz adds
#: one, 8 s four, each of four quarter-second blocks [estimate: long enough for the
#: diagnosis' test over blocks to see a separation of a few noise units].
PLAN_S = 8.0
PLAN_CYCLES = 4
DWELL_START_S, DWELL_END_S = 0.5, 1.0


@dataclass(frozen=True)
class Candidate:
    """A motion the search considers."""

    spec: SignalSpec
    mass_kg: float

    def describe(self) -> str:
        """'a 4 Hz trapezoid of 25 mm with 8.131 kg' and the like."""
        kind = {
            Shape.RECTANGULAR: "rectangle",
            Shape.TRAPEZOIDAL: "trapezoid",
            Shape.QUASI_SINUSOIDAL: "quasi-sine",
        }[self.spec.shape]
        return (
            f"a {self.spec.frequency_hz:g} Hz {kind} of {self.spec.amplitude_m * 1e3:g} mm "
            f"with {self.mass_kg:g} kg"
        )


def motion_grid(limits: DriveLimits, masses_kg: Sequence[float]) -> list[Candidate]:
    """Every grid motion the drive can make, in a fixed scattered order.

    The order is a seeded permutation, so that a search cut short by its budget has
    still seen the whole range coarsely.
    """
    grid = []
    for shape, a_mm, f_hz, mass in itertools.product(
        Shape, AMPLITUDES_MM, FREQUENCIES_HZ, masses_kg
    ):
        ramps = RAMP_FRACTIONS if shape is Shape.TRAPEZOIDAL else (0.25,)
        for ramp in ramps:
            cycles = max(2, round(MOTION_S * f_hz))
            spec = SignalSpec(shape, a_mm / 1e3, f_hz, cycles, ramp, DWELL_START_S, DWELL_END_S)
            try:
                plan_motion(spec, limits)
            except LimitError:
                continue
            grid.append(Candidate(spec, mass))
    order = np.random.default_rng(0).permutation(len(grid))
    return [grid[i] for i in order]


def padded(
    candidates: Sequence[Candidate], limits: DriveLimits, rate_hz: float
) -> tuple[FloatArray, list[int]]:
    """The motions' drive positions padded with rest to one length, and their lengths."""
    xs = [plan_motion(c.spec, limits).sample(rate_hz)[1] for c in candidates]
    n = max(x.size for x in xs)
    out = np.zeros((len(xs), n))
    for row, x in zip(out, xs, strict=True):
        row[: x.size] = x
    return out, [x.size for x in xs]


def lengthened(candidate: Candidate, limits: DriveLimits) -> Candidate:
    """The same motion run for ``PLAN_S`` (at least ``PLAN_CYCLES`` cycles)."""
    cycles = max(PLAN_CYCLES, round(PLAN_S * candidate.spec.frequency_hz))
    spec = dataclasses.replace(candidate.spec, cycles=cycles)
    plan_motion(spec, limits)  # the same rates and strokes: within the drive's limits
    return Candidate(spec, candidate.mass_kg)
