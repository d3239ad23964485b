"""Gauge calibration: raw counts of the 2 kHz front end to SI values (and back)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class GaugeCalibration:
    """Linear count → value conversion of the gauge front end's three channels.

    Attributes
    ----------
    force_n_per_count
        Force gauge scale, N per count (default 1 mN per count [estimate]).
    force_offset_n
        Force reading at zero counts, N.
    position_mm_per_count
        Displacement gauge (weight position u) scale, mm per count (default 0.1 µm per
        count [estimate]).
    position_offset_mm
        Displacement reading at zero counts, mm.
    drive_mm_per_count
        Drive encoder channel (drive position x) scale, mm per count (default 0.1 µm
        per count [estimate]).
    drive_offset_mm
        Drive position at zero counts, mm.
    """

    force_n_per_count: float = 1e-3
    force_offset_n: float = 0.0
    position_mm_per_count: float = 1e-4
    position_offset_mm: float = 0.0
    drive_mm_per_count: float = 1e-4
    drive_offset_mm: float = 0.0

    def force_n(self, counts: int | float) -> float:
        """Counts → newtons."""
        return self.force_offset_n + self.force_n_per_count * counts

    def position_mm(self, counts: int | float) -> float:
        """Counts → millimetres."""
        return self.position_offset_mm + self.position_mm_per_count * counts

    def drive_mm(self, counts: int | float) -> float:
        """Drive encoder counts → millimetres."""
        return self.drive_offset_mm + self.drive_mm_per_count * counts

    def force_counts(self, force_n: float) -> int:
        """Newtons → nearest count (what a front end would send)."""
        return round((force_n - self.force_offset_n) / self.force_n_per_count)

    def position_counts(self, position_mm: float) -> int:
        """Millimetres → nearest count."""
        return round((position_mm - self.position_offset_mm) / self.position_mm_per_count)

    def drive_counts(self, position_mm: float) -> int:
        """Drive position, mm → nearest count."""
        return round((position_mm - self.drive_offset_mm) / self.drive_mm_per_count)

    def to_si(
        self, force: NDArray[np.integer], weight: NDArray[np.integer], drive: NDArray[np.integer]
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Count arrays → (force N, weight position u mm, drive position x mm)."""
        return (
            self.force_offset_n + self.force_n_per_count * np.asarray(force, np.float64),
            self.position_offset_mm + self.position_mm_per_count * np.asarray(weight, np.float64),
            self.drive_offset_mm + self.drive_mm_per_count * np.asarray(drive, np.float64),
        )

    def to_counts(
        self, force_n: FloatArray, weight_mm: FloatArray, drive_mm: FloatArray
    ) -> tuple[NDArray[np.int32], NDArray[np.int32], NDArray[np.int32]]:
        """SI arrays → nearest counts, clipped to the i32 range of the frame."""

        def counts(value: FloatArray, offset: float, scale: float) -> NDArray[np.int32]:
            raw = np.rint((np.asarray(value, np.float64) - offset) / scale)
            return np.clip(raw, -(2**31), 2**31 - 1).astype(np.int32)

        return (
            counts(force_n, self.force_offset_n, self.force_n_per_count),
            counts(weight_mm, self.position_offset_mm, self.position_mm_per_count),
            counts(drive_mm, self.drive_offset_mm, self.drive_mm_per_count),
        )
