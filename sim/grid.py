"""Measured series on a uniform time grid: what replay and identification both start from.

A recording's samples arrive on a time base with gaps where samples were lost. Both the
model (which needs a drive position at every step) and the comparisons (which must leave
the lost samples out) want one uniform grid at the recording's own rate, with the drive
bridged across the gaps and the measured channels NaN there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

__all__ = ["MAX_GRID_FACTOR", "REST_TOLERANCE_M", "AlignedRun", "GridError", "align_arrays"]

#: The drive counts as at rest while within this distance of its first position, m.
REST_TOLERANCE_M = 0.05e-3
#: A grid may have at most this many points per sample (15 of 16 lost): the bound that
#: keeps a damaged time (a jump to 2⁶³ ns) from sizing arrays of terabytes. Readers
#: refuse such a recording first (``recordings.Recording.check``).
MAX_GRID_FACTOR = 16


class GridError(ValueError):
    """Series that cannot be put on a uniform grid (too short, no drive motion, bad times)."""


@dataclass(frozen=True)
class AlignedRun:
    """A recording on a uniform time grid (SI units); ``present`` marks real samples."""

    t_s: FloatArray
    x_m: FloatArray
    u_m: FloatArray
    force_n: FloatArray
    present: BoolArray
    rate_hz: float
    rest_samples: int  # samples before the drive first moves

    @property
    def lost_samples(self) -> int:
        """Grid points the recording has no sample for."""
        return int(self.present.size - np.count_nonzero(self.present))


def _rate_from_times(t_s: FloatArray) -> float:
    steps = np.diff(t_s)
    if steps.size == 0 or not np.all(steps > 0):
        raise GridError("the time base is not strictly increasing")
    return float(1.0 / np.median(steps))


def align_arrays(
    t_s: FloatArray,
    x_m: FloatArray,
    u_m: FloatArray,
    force_n: FloatArray,
    rate_hz: float | None = None,
) -> AlignedRun:
    """Put measured x, u (m) and F (N) at times t_s (s) on a uniform grid at their rate."""
    t = np.asarray(t_s, dtype=np.float64)
    if t.size < 2:
        raise GridError(f"the recording has {t.size} sample(s); a run needs more")
    if not np.all(np.isfinite(t)):
        raise GridError("the time base has non-finite values")
    rate = rate_hz or _rate_from_times(t)
    slot = np.rint((t - t[0]) * rate).astype(np.int64)
    if np.any(np.diff(slot) <= 0):
        raise GridError("samples do not fall on a uniform grid at the recording's rate")
    n = int(slot[-1]) + 1
    if n > MAX_GRID_FACTOR * t.size:
        raise GridError(
            f"the samples span {n} grid points at {rate:g} Hz for {t.size} samples: "
            f"more than {MAX_GRID_FACTOR - 1} of {MAX_GRID_FACTOR} missing"
        )
    grid_t = t[0] + np.arange(n) / rate
    present = np.zeros(n, dtype=bool)
    present[slot] = True

    def on_grid(values: FloatArray) -> FloatArray:
        out = np.full(n, np.nan)
        out[slot] = values
        return out

    x_rec = np.asarray(x_m, dtype=np.float64)
    if not np.all(np.isfinite(x_rec)):
        raise GridError("the drive position has non-finite values")
    x = np.interp(grid_t, t, x_rec)  # bridges lost samples for the model
    u = on_grid(np.asarray(u_m, dtype=np.float64))
    f = on_grid(np.asarray(force_n, dtype=np.float64))
    moving = np.flatnonzero(np.abs(x - x[0]) > REST_TOLERANCE_M)
    if not moving.size:
        raise GridError("the drive never moves in this recording: nothing to compare")
    # The weight reacts before x has moved by the tolerance: keep a 20 ms margin.
    rest = max(1, int(moving[0]) - int(0.02 * rate))
    return AlignedRun(grid_t - grid_t[0], x, u, f, present, rate, rest)
