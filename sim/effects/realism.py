"""Making simulated runs look like recordings of a real stand.

* ``NoiseSpec`` / ``MeasurementNoise``: white Gaussian noise on both gauges, mains hum
  (50 Hz, small, random phase) and quantisation to the front end's counts (1 mN,
  0.1 µm, as ``drivers.calibration.GaugeCalibration``'s defaults). ``MeasurementNoise``
  works block by block with a continuous hum phase (for the simulated stand);
  ``add_measurement_noise`` applies it to a whole run.
* ``draw_real_stand``: a stand whose stiffness, damping and friction scale differ from
  the nominal ones, as a real stand's do (uniform within ±spread).

Everything random takes a ``numpy.random.Generator``, so a seed reproduces a run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from sim.params import StandParams
from sim.results import SimResult

FloatArray = NDArray[np.float64]

__all__ = ["MeasurementNoise", "NoiseSpec", "add_measurement_noise", "draw_real_stand"]


@dataclass(frozen=True)
class NoiseSpec:
    """Measurement imperfections of the gauges (SI units).

    Attributes
    ----------
    force_rms_n
        White noise on the force channel, N rms (real-like: 0.05–0.2 N).
    displacement_rms_m
        White noise on the displacement channel, m rms (real-like: 2–10 µm).
    force_lsb_n
        Force quantisation step, N (1 mN counts).
    displacement_lsb_m
        Displacement quantisation step, m (0.1 µm counts).
    hum_force_n
        Mains hum amplitude on the force channel, N.
    hum_displacement_m
        Mains hum amplitude on the displacement channel, m.
    mains_hz
        Mains frequency, Hz.
    """

    force_rms_n: float = 0.1
    displacement_rms_m: float = 5e-6
    force_lsb_n: float = 1e-3
    displacement_lsb_m: float = 1e-7
    hum_force_n: float = 0.03
    hum_displacement_m: float = 1e-6
    mains_hz: float = 50.0

    @classmethod
    def draw(cls, rng: np.random.Generator) -> NoiseSpec:
        """Random real-like levels: noise within the ranges above, hum up to half of it."""
        force = float(rng.uniform(0.05, 0.2))
        disp = float(rng.uniform(2e-6, 10e-6))
        return cls(
            force_rms_n=force,
            displacement_rms_m=disp,
            hum_force_n=float(rng.uniform(0.0, 0.5)) * force,
            hum_displacement_m=float(rng.uniform(0.0, 0.5)) * disp,
        )


def _quantise(values: FloatArray, lsb: float) -> FloatArray:
    if lsb <= 0:
        return values
    out: FloatArray = np.round(values / lsb) * lsb
    return out


class MeasurementNoise:
    """Noise, hum and quantisation for a stream of samples at ``rate_hz``.

    Consecutive ``apply`` calls continue the same noise and hum: blocks of any size give
    the same result as one call over their concatenation (for the same generator state).
    """

    def __init__(self, spec: NoiseSpec, rate_hz: float, rng: np.random.Generator) -> None:
        self.spec = spec
        self.rate_hz = rate_hz
        self._rng = rng
        self._phase_f = float(rng.uniform(0.0, 2 * math.pi))
        self._phase_u = float(rng.uniform(0.0, 2 * math.pi))
        self._done = 0  # samples already produced (time is i/rate, never summed)

    def apply(self, u_m: FloatArray, force_n: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Recorded-like (u, F) for the next samples of the true (u, F)."""
        u = np.asarray(u_m, dtype=np.float64)
        f = np.asarray(force_n, dtype=np.float64)
        if u.shape != f.shape or u.ndim != 1:
            raise ValueError(f"u and F must be 1-D of one length, got {u.shape} and {f.shape}")
        s = self.spec
        t = (self._done + np.arange(u.shape[0])) / self.rate_hz
        self._done += u.shape[0]
        w = 2 * math.pi * s.mains_hz * t
        noise = self._rng.standard_normal((u.shape[0], 2))  # sample by sample: block-invariant
        hum_u = s.hum_displacement_m * np.sin(w + self._phase_u)
        u_out = u + s.displacement_rms_m * noise[:, 0] + hum_u
        f_out = f + s.force_rms_n * noise[:, 1] + s.hum_force_n * np.sin(w + self._phase_f)
        return _quantise(u_out, s.displacement_lsb_m), _quantise(f_out, s.force_lsb_n)


def add_measurement_noise(
    result: SimResult, rng: np.random.Generator, spec: NoiseSpec | None = None
) -> SimResult:
    """A copy of ``result`` whose u and F carry the gauges' noise, hum and quantisation.

    The drive channel x and the true velocity stay as they were.
    """
    rate = 1.0 / float(result.t_s[1] - result.t_s[0]) if result.t_s.shape[0] > 1 else 1.0
    noise = MeasurementNoise(spec or NoiseSpec(), rate, rng)
    u, f = noise.apply(result.u_m, result.force_n)
    return replace(result, u_m=u, force_n=f)


def draw_real_stand(
    nominal: StandParams, rng: np.random.Generator, spread: float = 0.25
) -> StandParams:
    """A "real" stand: stiffness, damping and friction scale × U(1 − spread, 1 + spread)."""
    if not 0 <= spread < 1:
        raise ValueError(f"spread must be in [0, 1), got {spread}")
    k, c, fs = rng.uniform(1 - spread, 1 + spread, size=3)
    return nominal.with_(
        stiffness_n_m=nominal.stiffness_n_m * float(k),
        damping_n_s_m=nominal.damping_n_s_m * float(c),
        friction_scale=nominal.friction_scale * float(fs),
    )
