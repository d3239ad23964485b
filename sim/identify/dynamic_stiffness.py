"""The fibre's stiffness against the rate it is strained at, read off its law in the recordings.

Fits per recording compare whole recordings, and a stand's recordings often strain the
fibre at much the same rates whatever the drive does: the weight bounces at its own
frequency (about 10 Hz heavy, 17 Hz light) in every one. A relaxation branch then adds
nearly the same stiffness to each, and the per-recording stiffness shows no trend with
the drive rate. Within each recording, though, the fibre is strained slowly by the
drive's motion and quickly by the bounce. So the fibre's law read off the recordings
(``balance.fibre_law``: F = k·e + c·ė on a taut fibre) gets a Prony series of relaxation
branches at fixed times τⱼ (the generalised Maxwell model: F += Σ aⱼ·(e − eⱼ),
τⱼ·ėⱼ = e − eⱼ), fitted by least squares on the training cycles. Its storage stiffness

    k′(f) = k + Σ aⱼ·(2πfτⱼ)² / (1 + (2πfτⱼ)²)

is the fibre's stiffness at each rate; a Kelvin–Voigt fibre's is flat. Two one-sided
tests at ``ALPHA``, and both must pass, say that it rises with the rate:

* **held out**: the branches lower the held-out cycles' error of the law by more than
  they lower the fitted model's own (its outputs read through the same steps: the
  low-pass and the two spans and pulley taken as one spring leave a little in any law,
  and with thousands of samples a little is significant). A t over the held-out cycles.
* **the rise**: k′ from the slowest drive rate to the fastest strain rate among the
  recordings, less the model's own rise, is above zero. A t with the error of a
  delete-one-cycle jackknife over the training cycles.

Computed for the baseline alone (the paper's question: does one stiffness do for quick
and slow tests?) and, where effects are named, for the final model (did they take it
out?).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.signal import lfilter

from sim.identify.balance import FibreLaw, fibre_law
from sim.identify.heldout import Outputs
from sim.identify.per_recording import CONSISTENCY_ALPHA, POINTS_TO, drive_of
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

__all__ = ["RELAXATION_TIMES_S", "RateDependence", "rate_dependence"]

#: The Prony series' relaxation times, s: corners 1/(2πτ) of 16, 5.3, 1.6 and 0.5 Hz,
#: spanning the rates a stand strains its fibre at, from the drive's slowest motions
#: (about 0.4 Hz) to the light weight's bounce (about 20 Hz).
RELAXATION_TIMES_S = (0.01, 0.03, 0.1, 0.3)
#: Each of the two tests' false-alarm rate (as the per-recording consistency tests).
ALPHA = CONSISTENCY_ALPHA
#: A held-out cycle counts where the law can be read on at least this many samples.
MIN_SAMPLES = 50
#: Points of the reported curve k′(f), log-spaced between the two rates.
CURVE_POINTS = 9


@dataclass(frozen=True)
class RateDependence:
    """The fibre's storage stiffness against the strain rate, and whether it rises."""

    frequencies_hz: list[float]
    #: k′(f) read off the recordings, as a multiple of the nominal stiffness.
    stiffness_scale: list[float]
    intervals: list[tuple[float, float]]
    #: The fitted model's own k′(f), read off its outputs through the same steps.
    model_stiffness_scale: list[float]
    slowest_drive_hz: float
    fastest_strain_hz: float
    #: k′(fastest) − k′(slowest), recorded less the model's own (nominal stiffness units).
    rise: float
    rise_interval: tuple[float, float]
    p_heldout: float
    p_rise: float
    cycles_heldout: int
    cycles_training: int
    #: Read against a model with effects named: the baseline alone's rise, which they
    #: should take out (None for the baseline alone itself).
    alone_rise: float | None = None
    #: Read against a model with effects named (not the baseline alone).
    named: bool = False

    @property
    def rises(self) -> bool:
        """Both tests pass: the fibre is stiffer the quicker it is strained than the model."""
        return self.p_heldout < ALPHA and self.p_rise < ALPHA and self.rise > 0

    @property
    def explained_share(self) -> float | None:
        """The share of the baseline alone's rise the named effects' model has too."""
        if self.alone_rise is None or not self.alone_rise > 0:
            return None
        return 1.0 - self.rise / self.alone_rise

    @property
    def trend(self) -> str:
        """In words, with the numbers."""
        first, last = self.stiffness_scale[0], self.stiffness_scale[-1]
        span = (
            f"×{first:.3g} at {self.slowest_drive_hz:.2g} Hz to ×{last:.3g} at "
            f"{self.fastest_strain_hz:.2g} Hz (the model's own ×{self.model_stiffness_scale[0]:.3g}"
            f" to ×{self.model_stiffness_scale[-1]:.3g}; p {self.p_heldout:.2g} held out, "
            f"{self.p_rise:.2g} for the rise)"
        )
        share = self.explained_share
        if share is not None:
            # With effects named the model's own curve rises too; the question is how much
            # of the rise it has, and what is left beyond it (a precise reading finds a
            # rest of a per cent from parameters off by their own interval's width).
            low, high = self.rise_interval
            return (
                f"the named effects' model has {share:.0%} of the baseline alone's rise with "
                f"the strain rate: {span}; beyond it {self.rise:+.2g} [{low:+.2g}, {high:+.2g}]"
            )
        if self.rises:
            beyond = ", beyond the named effects' model" if self.named else ""
            return f"the fibre's stiffness rises with the rate it is strained at{beyond}: {span}"
        return f"no rise of the fibre's stiffness with the strain rate beyond the model's: {span}"

    def to_dict(self) -> dict[str, Any]:
        """JSON: the curve, both rates, the rise with its interval, both p-values, the flag."""
        return {
            "frequencies_hz": self.frequencies_hz,
            "stiffness_scale": self.stiffness_scale,
            "intervals": [list(i) for i in self.intervals],
            "model_stiffness_scale": self.model_stiffness_scale,
            "slowest_drive_hz": self.slowest_drive_hz,
            "fastest_strain_hz": self.fastest_strain_hz,
            "rise": self.rise,
            "rise_interval": list(self.rise_interval),
            "p_heldout": self.p_heldout,
            "p_rise": self.p_rise,
            "cycles_heldout": self.cycles_heldout,
            "cycles_training": self.cycles_training,
            "rises_with_rate": self.rises,
            "explained_share": self.explained_share,
            "trend": self.trend,
            "points_to": self.points_to,
        }

    @property
    def points_to(self) -> str | None:
        """A relaxation branch, where the rise is beyond the model read against.

        Against a model with effects named, only where they have less than half of the
        baseline alone's rise: a precise reading finds a significant rest of a per cent
        behind a branch that is named, off by its own interval's width.
        """
        if not self.rises:
            return None
        branch = POINTS_TO[("stiffness_scale", "drive_rate_hz", 1)]
        if not self.named:
            return branch
        share = self.explained_share
        return f"beyond the named effects, {branch}" if share is None or share < 0.5 else None


def _branch_strains(e: FloatArray, rate_hz: float) -> list[FloatArray]:
    """e − eⱼ for each τⱼ: each branch's spring, from rest at the trace's start."""
    out = []
    for tau in RELAXATION_TIMES_S:
        a = math.exp(-1.0 / (tau * rate_hz))
        lagged = lfilter([1.0 - a], [1.0, -a], e - e[0]) + e[0]
        out.append(np.asarray(e - lagged, dtype=np.float64))
    return out


def _design(law: FibreLaw, rate_hz: float, recording: int, recordings: int) -> FloatArray:
    """Columns: an offset per recording, e, ė, then the branches' strains."""
    offsets = np.zeros((law.e.size, recordings))
    offsets[:, recording] = 1.0
    return np.column_stack([offsets, law.e, law.e_rate, *_branch_strains(law.e, rate_hz)])


@dataclass
class _Units:
    """The law's normal equations per cycle (a jackknife's unit), and the held-out parts."""

    gram: dict[tuple[int, int], FloatArray]
    moment: dict[tuple[int, int], FloatArray]
    heldout: list[tuple[FloatArray, FloatArray]]  # (design, force) per held-out cycle


def _units(traces: Sequence[Trace], laws: Sequence[FibreLaw], usable: Sequence[BoolArray],
           scale: FloatArray) -> _Units:  # fmt: skip
    gram, moment, heldout = {}, {}, []
    for i, (tr, law, use) in enumerate(zip(traces, laws, usable, strict=True)):
        x = _design(law, tr.rate_hz, i, len(traces)) / scale
        for c in np.unique(tr.cycle[tr.train & use]):
            m = tr.train & use & (tr.cycle == c)
            gram[(i, int(c))] = x[m].T @ x[m]
            moment[(i, int(c))] = x[m].T @ law.force[m]
        for c in np.unique(tr.cycle[tr.test & use]):
            m = tr.test & use & (tr.cycle == c)
            if m.sum() >= MIN_SAMPLES:
                heldout.append((x[m], law.force[m]))
    return _Units(gram, moment, heldout)


def _solve(u: _Units, columns: int, leave_out: tuple[int, int] | None = None) -> FloatArray:
    keys = [k for k in u.gram if k != leave_out]
    g = np.sum([u.gram[k] for k in keys], axis=0)[:columns, :columns]
    b = np.sum([u.moment[k] for k in keys], axis=0)[:columns]
    return np.asarray(np.linalg.lstsq(g, b, rcond=None)[0], dtype=np.float64)


def _heldout_gains(u: _Units, columns: int) -> FloatArray:
    """Per held-out cycle: the mean squared error of the law without the branches less with."""
    plain, full = _solve(u, columns - len(RELAXATION_TIMES_S)), _solve(u, columns)
    return np.array([
        np.mean((f - x[:, : plain.size] @ plain) ** 2) - np.mean((f - x @ full) ** 2)
        for x, f in u.heldout
    ])  # fmt: skip


def _storage(beta: FloatArray, scale: FloatArray, recordings: int, f_hz: FloatArray) -> FloatArray:
    """k′(f), N/m, from the fitted (scaled) coefficients."""
    coef = beta / scale
    k, branches = coef[recordings], coef[recordings + 2 :]
    w = 2 * np.pi * np.asarray(f_hz)[:, None]
    taus = np.array(RELAXATION_TIMES_S)[None, :]
    return np.asarray(k + ((w * taus) ** 2 / (1 + (w * taus) ** 2)) @ branches, dtype=np.float64)


def _strain_rate_hz(law: FibreLaw, use: BoolArray) -> float:
    """The elongation's rms frequency, √(mean ė² / mean (e − ē)²) / 2π."""
    e, rate = law.e[use], law.e_rate[use]
    spread = float(np.mean((e - e.mean()) ** 2)) if e.size else 0.0
    return math.sqrt(float(np.mean(rate**2)) / spread) / (2 * math.pi) if spread > 0 else 0.0


def _one_sided(values: FloatArray) -> float:
    """p of mean > 0 (Student t); 1 where there is nothing to test."""
    if values.size < 2 or not np.std(values) > 0:
        return 1.0
    t = float(np.mean(values) / (np.std(values, ddof=1) / math.sqrt(values.size)))
    return float(stats.t.sf(t, values.size - 1))


def rate_dependence(
    traces: Sequence[Trace],
    nominal: StandParams,
    values: dict[str, float],
    outputs: Sequence[Outputs],
    alone: RateDependence | None = None,
    named: bool = False,
) -> RateDependence | None:
    """The fibre's storage stiffness against the strain rate, recorded and the model's own.

    ``values`` and ``outputs``: the fitted model (its stiffness and damping place the
    taut fibre; its outputs are the null). None where the law cannot be read on at least
    two held-out and three training cycles, or the recordings strain the fibre at one
    rate only. ``named``: the model has effects named; ``alone``: then the baseline
    alone's reading (its rise is what they should take out).
    """
    rec = [fibre_law(tr, nominal, values) for tr in traces]
    own = [fibre_law(tr, nominal, values, o) for tr, o in zip(traces, outputs, strict=True)]
    usable = [r.usable & o.usable for r, o in zip(rec, own, strict=True)]
    n = len(traces)
    columns = n + 2 + len(RELAXATION_TIMES_S)
    parts = list(zip(traces, rec, usable, strict=True))
    stacked = np.vstack([_design(r, tr.rate_hz, i, n)[u] for i, (tr, r, u) in enumerate(parts)])
    if stacked.shape[0] == 0:
        return None
    # Each column to unit rms: the normal equations square the design's conditioning.
    scale = np.sqrt(np.mean(stacked**2, axis=0))
    scale[scale == 0] = 1.0
    u_rec, u_own = _units(traces, rec, usable, scale), _units(traces, own, usable, scale)
    slowest = min(drive_of(tr)["drive_rate_hz"] for tr in traces)
    fastest = max(_strain_rate_hz(r, u & tr.train) for tr, r, u in parts)
    if len(u_rec.heldout) < 2 or len(u_rec.gram) < 3 or not 0 < slowest < fastest:
        return None
    gains = _heldout_gains(u_rec, columns) - _heldout_gains(u_own, columns)
    freqs = np.geomspace(slowest, fastest, CURVE_POINTS)
    k_nominal = nominal.stiffness_n_m

    def curves(leave_out: tuple[int, int] | None) -> tuple[FloatArray, FloatArray]:
        recorded = _storage(_solve(u_rec, columns, leave_out), scale, n, freqs) / k_nominal
        model = _storage(_solve(u_own, columns, leave_out), scale, n, freqs) / k_nominal
        return recorded, model

    recorded, model = curves(None)
    rise = float((recorded[-1] - recorded[0]) - (model[-1] - model[0]))
    units = list(u_rec.gram)
    jack = [curves(k) for k in units]
    m = len(units)
    jack_rise = np.array([(r[-1] - r[0]) - (o[-1] - o[0]) for r, o in jack])
    spread = math.sqrt((m - 1) / m * float(np.sum((jack_rise - jack_rise.mean()) ** 2)))
    jack_curves = np.array([r for r, _ in jack])
    curve_se = np.sqrt((m - 1) / m * np.sum((jack_curves - jack_curves.mean(axis=0)) ** 2, axis=0))
    t95 = float(stats.t.ppf(0.975, m - 1))
    p_rise = float(stats.t.sf(rise / spread, m - 1)) if spread > 0 else (0.0 if rise > 0 else 1.0)
    return RateDependence(
        frequencies_hz=[float(f) for f in freqs],
        stiffness_scale=[float(v) for v in recorded],
        intervals=[
            (float(v - t95 * s), float(v + t95 * s))
            for v, s in zip(recorded, curve_se, strict=True)
        ],
        model_stiffness_scale=[float(v) for v in model],
        slowest_drive_hz=float(slowest),
        fastest_strain_hz=float(fastest),
        rise=rise,
        rise_interval=(rise - t95 * spread, rise + t95 * spread),
        p_heldout=_one_sided(gains),
        p_rise=p_rise,
        cycles_heldout=int(gains.size),
        cycles_training=m,
        alone_rise=alone.rise if alone is not None and alone.rises else None,
        named=named,
    )
