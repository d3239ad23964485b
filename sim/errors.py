"""The model's error root (light: no numerics imported)."""

from __future__ import annotations

__all__ = ["SimulationError"]


class SimulationError(ValueError):
    """The model's inputs are unusable (non-finite, too short, bad rate, unknown effect)."""
