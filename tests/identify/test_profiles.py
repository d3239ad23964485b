"""An interval's ends carried out along its profile where the cost stays as low."""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numpy.typing import NDArray

from sim.identify.fitting import Candidate, Objective
from sim.identify.intervals import along_profiles

FloatArray = NDArray[np.float64]
HALF = 0.05  # each interval's half-width, in the optimiser's coordinates


class _Cost:
    """The few members of ``Objective`` the profile uses, over a residual function."""

    def __init__(self, candidate: Candidate, residual_of: object) -> None:
        self.candidate, self.simulations = candidate, 0
        self._of = residual_of

    def residuals(self, z: FloatArray) -> FloatArray:
        self.simulations += 1
        return np.asarray(self._of(z))  # type: ignore[operator]

    def residuals_batch(self, zs: FloatArray) -> FloatArray:
        return np.stack([self.residuals(z) for z in zs])

    def jacobian(self, z: FloatArray, columns: NDArray[np.bool_], steps: FloatArray) -> FloatArray:
        base = self.residuals(z)  # forward secants, as the objective takes them
        cols = []
        for i in np.flatnonzero(columns):
            moved = z.copy()
            moved[i] += steps[i]
            cols.append((self.residuals(moved) - base) / steps[i])
        return np.column_stack(cols)


def _ends(
    residual_of: object,
) -> tuple[dict[str, tuple[float, float]], dict[str, tuple[float, float]]]:
    candidate = Candidate.build()
    z = candidate.internal({"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 0.5})
    free = np.ones(z.size, dtype=bool)
    ends = {
        p.name: (float(z[k] - HALF), float(z[k] + HALF)) for k, p in enumerate(candidate.params)
    }
    cost = _Cost(candidate, lambda y: residual_of(y - z))  # type: ignore[operator]
    got, sims = along_profiles(cast("Objective", cost), candidate, z, free, ends)
    assert sims > 0
    return ends, got


def test_a_parabola_keeps_its_interval() -> None:
    ends, got = _ends(lambda d: d / 0.01)  # linear residuals: the cost is its quadratic
    for name, (lo, hi) in ends.items():
        assert got[name] == (lo, hi)


def test_a_second_valley_just_beyond_an_end_is_taken_in_and_the_interval_never_narrows() -> None:
    # The first parameter's cost rises to its level at the interval's end, then falls
    # again past a low ridge (as a pulley's inertia traded against its bearing torque);
    # the others are parabolas.
    def residual(d: FloatArray) -> FloatArray:
        return np.array([math.sin(math.pi * d[0] / (1.3 * HALF)), d[1] / 0.01, d[2] / 0.01])

    ends, got = _ends(residual)
    first, *others = ends
    (lo, hi), (new_lo, new_hi) = ends[first], got[first]
    centre = 0.5 * (lo + hi)
    # the cost at 1.5 half-widths is below its level at the end, at 2 above it
    assert math.isclose(new_hi - centre, 1.5 * HALF) and math.isclose(centre - new_lo, 1.5 * HALF)
    for name in others:
        assert got[name] == ends[name]
    for name, (a, b) in ends.items():
        assert got[name][0] <= a and got[name][1] >= b
