"""The other stand's measurement chain: gauge effects, sampling, noise, quantisation.

The physics runs at ``over`` × the sample rate; the gauges act on that fine signal as an
analogue front end would (load cell and amplifier, dial gauge mechanics), the recorder
then samples it — late or early for a skewed channel — and the samples carry noise, hum
and the front end's quantisation (``Realism``, the levels of shared/validation/README.md).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy.signal import cont2discrete, lfilter, lfilter_zi

from sim.checks.otherstand.outside import force_drift

FloatArray = NDArray[np.float64]

__all__ = ["Realism", "dial_gauge", "force_gauge", "record", "sample_delayed"]


@njit(cache=True)
def _play(u, width):  # type: ignore[no-untyped-def]
    """Backlash (play operator): the output moves only once the input has taken up the play."""
    out = np.empty_like(u)
    y = u[0]
    half = width / 2.0
    for i in range(u.shape[0]):
        if u[i] > y + half:
            y = u[i] - half
        elif u[i] < y - half:
            y = u[i] + half
        out[i] = y
    return out


def dial_gauge(u_m: FloatArray, params: Mapping[str, float]) -> FloatArray:
    """Reading = offset + gain·b + curvature·b², b the displacement after the backlash."""
    b = np.asarray(_play(np.ascontiguousarray(u_m), float(params["backlash_m"])))
    out: FloatArray = params["offset_m"] + params["gain"] * b + params["curvature_1_m"] * b * b
    return out


def force_gauge(force_n: FloatArray, rate_hz: float, params: Mapping[str, float]) -> FloatArray:
    """The force through the load cell's resonance and a first-order amplifier.

    Settled at the first value, unity static gain; a zero cutoff or frequency leaves that
    stage out.
    """
    num = np.array([1.0])
    den = np.array([1.0])
    fa = params["amplifier_cutoff_hz"]
    if fa > 0:
        den = np.polymul(den, [1.0 / (2 * math.pi * fa), 1.0])
    fc = params["cell_frequency_hz"]
    if fc > 0:
        w = 2 * math.pi * fc
        den = np.polymul(den, [1.0 / w**2, 2 * params["cell_damping"] / w, 1.0])
    if den.size == 1:
        return np.asarray(force_n, dtype=np.float64)
    numd, dend, _ = cont2discrete((num, den), 1.0 / rate_hz, method="foh")
    b = np.ravel(numd)
    zi = lfilter_zi(b, dend) * force_n[0]
    out, _ = lfilter(b, dend, force_n, zi=zi)
    return np.asarray(out, dtype=np.float64)


def sample_delayed(signal: FloatArray, over: int, delay_s: float, rate_hz: float) -> FloatArray:
    """Samples at i/rate − delay of a signal given at rate·over (``delay_s`` < 0: early).

    Four-point Lagrange interpolation on the fine grid; held beyond the ends.
    """
    n = (signal.shape[0] - 1) // over + 1
    pos = np.arange(n) * over - delay_s * rate_hz * over  # fine-grid position
    last = signal.shape[0] - 1
    pos = np.clip(pos, 0.0, float(last))
    j = np.clip(np.floor(pos).astype(np.int64), 1, max(last - 2, 1))
    f = pos - j
    idx = [np.clip(j + d, 0, last) for d in (-1, 0, 1, 2)]
    w = (
        -f * (f - 1) * (f - 2) / 6,
        (f + 1) * (f - 1) * (f - 2) / 2,
        -(f + 1) * f * (f - 2) / 2,
        (f + 1) * f * (f - 1) / 6,
    )
    out: FloatArray = sum((wk * signal[ik] for wk, ik in zip(w, idx, strict=True)), np.zeros(n))
    return out


@dataclass(frozen=True)
class Realism:
    """Noise and quantisation of the recorder (the validation set's levels, SI).

    The artefacts a real acquisition adds, off by default (``with_artefacts``): a third
    mains harmonic, sample-clock jitter, lost samples in short bursts, single-sample
    spikes on the force channel.
    """

    force_rms_n: float = 0.3
    hum_n: float = 0.2
    mains_hz: float = 50.0
    force_lsb_n: float = 1e-3
    displacement_rms_m: float = 5e-6
    displacement_lsb_m: float = 1e-5
    drive_lsb_m: float = 1e-6
    hum_harmonic_n: float = 0.0  # at 3 × mains
    jitter_s: float = 0.0  # rms of each sample's time error
    lost_share: float = 0.0  # of the samples, lost in bursts of 1–20
    spikes_per_s: float = 0.0  # single-sample force spikes
    spike_n: float = 0.0  # their typical size

    @classmethod
    def with_artefacts(cls, rng: np.random.Generator) -> Realism:
        """The default levels plus drawn artefacts (what a stand's recorder really gives).

        150 Hz hum 0.05–0.2 N (a rectifier's third harmonic), clock jitter 2–20 µs rms (a
        USB serial bridge's), 0.1–1 % of the samples lost, 0.2–2 spikes per second of
        2–15 N (a loose connector).
        """
        return cls(
            hum_harmonic_n=float(rng.uniform(0.05, 0.2)),
            jitter_s=float(np.exp(rng.uniform(np.log(2e-6), np.log(2e-5)))),
            lost_share=float(rng.uniform(1e-3, 1e-2)),
            spikes_per_s=float(rng.uniform(0.2, 2.0)),
            spike_n=float(rng.uniform(2.0, 15.0)),
        )

    def apply(
        self, x_m: FloatArray, u_m: FloatArray, force_n: FloatArray, rate_hz: float,
        rng: np.random.Generator,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:  # fmt: skip
        """Recorded (x, u, F): quantised encoder; noisy, quantised dial; noisy, humming force.

        Lost samples are NaN in u and F.
        """
        n = x_m.shape[0]
        t = np.arange(n) / rate_hz
        if self.jitter_s > 0:  # each sample taken a little off its time: first order
            dt = self.jitter_s * rng.standard_normal(n)
            x_m = x_m + np.gradient(x_m, t) * dt
            u_m = u_m + np.gradient(u_m, t) * dt
            force_n = force_n + np.gradient(force_n, t) * dt
        phase = rng.uniform(0, 2 * math.pi)
        hum = self.hum_n * np.sin(2 * math.pi * self.mains_hz * t + phase)
        hum += self.hum_harmonic_n * np.sin(6 * math.pi * self.mains_hz * t + 3 * phase)
        f = force_n + self.force_rms_n * rng.standard_normal(n) + hum
        u = u_m + self.displacement_rms_m * rng.standard_normal(n)
        if self.spikes_per_s > 0:
            at = rng.integers(0, n, size=rng.poisson(self.spikes_per_s * n / rate_hz))
            f[at] += (
                self.spike_n
                * rng.choice([-1.0, 1.0], size=at.size)
                * rng.uniform(0.5, 1.5, size=at.size)
            )
        q = np.round
        u_out = q(u / self.displacement_lsb_m) * self.displacement_lsb_m
        f_out = q(f / self.force_lsb_n) * self.force_lsb_n
        if self.lost_share > 0:
            lost = _lost_bursts(n, self.lost_share, rng)
            u_out[lost] = np.nan
            f_out[lost] = np.nan
        return q(x_m / self.drive_lsb_m) * self.drive_lsb_m, u_out, f_out


def _lost_bursts(n: int, share: float, rng: np.random.Generator) -> NDArray[np.bool_]:
    """Samples lost in bursts of 1–20, about ``share`` of them, never the first second."""
    lost = np.zeros(n, dtype=bool)
    bursts = rng.poisson(share * n / 10.5)
    for start in rng.integers(min(n - 1, 2000), n, size=bursts):
        lost[start : start + int(rng.integers(1, 21))] = True
    return lost


def record(
    u_fine: FloatArray,
    force_fine: FloatArray,
    rate_hz: float,
    over: int,
    effects: Mapping[str, Mapping[str, float]],
) -> tuple[FloatArray, FloatArray]:
    """The noise-free recorded (u, F) at ``rate_hz`` from the fine true signals."""
    u = u_fine
    f = force_fine
    if "force_gauge_dynamics" in effects:
        f = force_gauge(f, rate_hz * over, effects["force_gauge_dynamics"])
    if "dial_gauge_calibration" in effects:
        u = dial_gauge(u, effects["dial_gauge_calibration"])
    if "force_gauge_drift" in effects:
        f = force_drift(f, rate_hz * over, effects["force_gauge_drift"])
    skew = effects.get("channel_time_skew", {})
    return (
        sample_delayed(u, over, float(skew.get("displacement_delay_s", 0.0)), rate_hz),
        sample_delayed(f, over, float(skew.get("force_delay_s", 0.0)), rate_hz),
    )
