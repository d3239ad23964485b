"""Gauge calibration: raw counts of the 2 kHz front end to SI values."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class GaugeCalibration:
    """Linear count → value conversion of the gauge front end.

    Attributes
    ----------
    force_n_per_count
        Force gauge scale, N per count (default 1 mN per count [estimate]).
    force_offset_n
        Force reading at zero counts, N.
    position_mm_per_count
        Displacement gauge scale, mm per count (default 0.1 µm per count [estimate]).
    position_offset_mm
        Displacement reading at zero counts, mm.
    """

    force_n_per_count: float = 1e-3
    force_offset_n: float = 0.0
    position_mm_per_count: float = 1e-4
    position_offset_mm: float = 0.0

    def force_n(self, counts: int | float) -> float:
        """Counts → newtons."""
        return self.force_offset_n + self.force_n_per_count * counts

    def position_mm(self, counts: int | float) -> float:
        """Counts → millimetres."""
        return self.position_offset_mm + self.position_mm_per_count * counts

    def force_counts(self, force_n: float) -> int:
        """Newtons → nearest count (what a front end would send)."""
        return round((force_n - self.force_offset_n) / self.force_n_per_count)

    def position_counts(self, position_mm: float) -> int:
        """Millimetres → nearest count."""
        return round((position_mm - self.position_offset_mm) / self.position_mm_per_count)
