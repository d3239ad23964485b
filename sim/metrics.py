"""The paper's comparison measures (STAND.md §4): R, ψ = (1 − R)², and NRMSE.

R is blind to gain and offset (a mis-calibrated gauge leaves it unchanged), so the gap
itself is measured with NRMSE = ‖x² − x¹‖ / ‖x¹ − μ₁‖ (x¹ recorded, x² simulated); R and
ψ are reported for comparison with the paper.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = ["ChannelMetrics", "channel_metrics", "correlation", "nrmse"]


@dataclass(frozen=True)
class ChannelMetrics:
    """How well one simulated (or second) series matches a recorded one."""

    R: float
    psi: float
    nrmse: float
    rms_error: float
    samples: int

    def to_dict(self) -> dict[str, float | int]:
        """Plain values (JSON keys R, psi, nrmse, rms_error, samples)."""
        return asdict(self)


def correlation(recorded: FloatArray, simulated: FloatArray) -> float:
    """The paper's correlation coefficient R (eq. 1); 0 when either series is constant."""
    a = recorded - recorded.mean()
    b = simulated - simulated.mean()
    denom = float(np.sqrt(np.dot(a, a) * np.dot(b, b)))
    return float(np.dot(a, b) / denom) if denom > 0 else 0.0


def nrmse(recorded: FloatArray, simulated: FloatArray) -> float:
    """‖x² − x¹‖ / ‖x¹ − μ₁‖; inf when the recorded series is constant."""
    spread = float(np.linalg.norm(recorded - recorded.mean()))
    err = float(np.linalg.norm(simulated - recorded))
    return err / spread if spread > 0 else float("inf")


def channel_metrics(recorded: FloatArray, simulated: FloatArray) -> ChannelMetrics:
    """R, ψ, NRMSE and RMS error of one channel over the samples both series have."""
    rec = np.asarray(recorded, dtype=np.float64)
    sim = np.asarray(simulated, dtype=np.float64)
    if rec.shape != sim.shape:
        raise ValueError(f"series differ in length: {rec.shape[0]} and {sim.shape[0]} samples")
    ok = np.isfinite(rec) & np.isfinite(sim)
    rec, sim = rec[ok], sim[ok]
    if rec.size < 2:
        raise ValueError("fewer than 2 samples to compare")
    r = correlation(rec, sim)
    rms = float(np.sqrt(np.mean((sim - rec) ** 2)))
    return ChannelMetrics(
        R=r, psi=(1.0 - r) ** 2, nrmse=nrmse(rec, sim), rms_error=rms, samples=int(rec.size)
    )
