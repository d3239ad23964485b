"""The model beside the measurement: the baseline fed the measured drive position.

``LiveModel`` advances ``sim.model.Model.stream`` (the physics the simulated stand runs
on) block by block with the gauges' x, so its u and F can be drawn next to the measured
ones while a run goes on, and their difference (the residual) shows a drift from the
model as it happens. Lost samples (sequence gaps) are bridged by holding or
interpolating x, as ``labstand replay`` bridges them, and give no output.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.model import Model, ModelStream
from sim.params import StandParams

FloatArray = NDArray[np.float64]

__all__ = ["LiveModel", "ModelBlock"]


@dataclass(frozen=True)
class ModelBlock:
    """The model at the samples of one gauges block, and measured − model.

    The model starts at rest (u = 0); its u is given on the gauge's scale, from the
    first sample's reading, so it plots over the measured u even if the gauge was not
    zeroed (the residual is then as in ``labstand replay``, both u from rest).
    """

    u_mm: FloatArray
    force_n: FloatArray
    residual_u_mm: FloatArray
    residual_force_n: FloatArray


class LiveModel:
    """The baseline model driven by a run's measured x, one gauges block at a time."""

    def __init__(self, params: StandParams, rate_hz: float) -> None:
        self._model = Model(params)
        self.rate_hz = rate_hz
        self._stream: ModelStream | None = None
        self._u_rest_mm = 0.0
        self._next_seq = 0
        self._last_x_m = 0.0

    def advance(self, block: NDArray[np.void]) -> ModelBlock:
        """The model at the block's samples (GAUGES_DTYPE: seq, x_mm, u_mm, force_n)."""
        if self._stream is not None and int(block["seq"][0]) < self._next_seq:
            block = block[block["seq"] >= self._next_seq]  # repeated samples: once only
        seq = np.asarray(block["seq"], dtype=np.int64)
        if len(seq) == 0:
            empty = np.empty(0)
            return ModelBlock(empty, empty, empty, empty)
        x_m = np.asarray(block["x_mm"], dtype=np.float64) * 1e-3
        if self._stream is None:
            self._stream = self._model.stream(self.rate_hz, x0_m=float(x_m[0]))
            self._u_rest_mm = float(block["u_mm"][0])
            self._next_seq, self._last_x_m = int(seq[0]), float(x_m[0])
        # every sample from the next expected one to the block's last, gaps bridged
        first = self._next_seq
        full = np.arange(first, int(seq[-1]) + 1)
        known_seq = np.concatenate(([self._next_seq - 1], seq))
        known_x = np.concatenate(([self._last_x_m], x_m))
        x_full = np.interp(full, known_seq, known_x) if len(full) != len(seq) else x_m
        u_m, force_n = self._stream.advance(np.ascontiguousarray(x_full, dtype=np.float64))
        pick = seq - first
        u_mm = u_m[pick] * 1e3 + self._u_rest_mm
        force = force_n[pick]
        self._next_seq, self._last_x_m = int(seq[-1]) + 1, float(x_m[-1])
        return ModelBlock(
            u_mm,
            force,
            np.asarray(block["u_mm"], dtype=np.float64) - u_mm,
            np.asarray(block["force_n"], dtype=np.float64) - force,
        )
