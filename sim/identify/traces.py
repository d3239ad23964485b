"""Recordings prepared for diagnosis: uniform grid, phases, cycles, held-out split.

A *trace* is one recording on its own uniform time grid with everything the fit and the
attribution need: the drive position that excites the model, the recorded u (from its
rest value) and F, which samples exist, the phase of the drive motion at every sample,
which cycle each sample belongs to, and whether it is used for fitting or held out.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy.signal import butter, sosfiltfilt, welch

from sim.grid import GridError, align_arrays
from sim.identify.shooting import Segments, segment_trace

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

PHASES = ("rise", "hold", "fall", "rest")
PHASE_RISE, PHASE_HOLD, PHASE_FALL, PHASE_REST = range(4)
#: The drive counts as moving above this speed, m/s.
MOVING_SPEED_M_S = 1e-3
#: A recording shorter than this cannot identify anything, s.
MIN_DURATION_S = 1.0
#: Less drive travel than this identifies nothing, m.
MIN_STROKE_M = 1e-3
#: The measured drive position drives the model after a zero-phase low-pass whose
#: cut-off is where the drive's own motion sinks below the encoder's noise (its
#: spectrum's floor, read from the top of the band, where a massive servo axis moves
#: nothing): encoder noise differentiated by the fibre damping (c·ẋ) would put broadband
#: noise into the model's force that candidates which smooth it (a gauge low-pass, a
#: Maxwell branch) then "explain", and a cut-off below the motion rounds every corner of
#: it into a force misfit that a resonance then "explains". Where signal and noise reach
#: the model's force through the same fibre, the cut that loses least is where their
#: spectra cross (the brick-wall Wiener filter).
#: Bands of the drive's spectrum compared with its noise floor (per octave, from 10 Hz).
DRIVE_BANDS_PER_OCTAVE = 4
#: The noise floor is the median spectral density over this share of the band (of Nyquist).
DRIVE_FLOOR_BAND = (0.6, 0.95)


class DiagnosisInputError(ValueError):
    """Recordings that cannot be diagnosed; the message says what is missing."""


@dataclass(frozen=True)
class Trace:
    """One recording ready for fitting (SI units, uniform grid at ``rate_hz``)."""

    name: str
    rate_hz: float
    mass_kg: float
    x_m: FloatArray
    u_m: FloatArray  # from the rest value; NaN where lost
    force_n: FloatArray  # absolute; NaN where lost
    present: BoolArray
    phase: IntArray
    cycle: IntArray  # -1 before the first cycle
    train: BoolArray  # used for fitting (the rest is held out)
    noise_u_m: float  # rms of u during the initial rest (sensor noise floor)
    noise_force_n: float
    stroke_m: float
    #: The campaign's dial gauge slope du/dx at constant force (``shooting.dial_slope``);
    #: NaN: estimated from this trace alone.
    dial_slope: float = float("nan")
    #: A fit's per-sample units of u (m) and F (N), in place of each channel's spread
    #: (``fitting.Objective``): a reference model's miss (``fitting.weighed_by_miss``).
    fit_units: tuple[float, float] | None = None

    @property
    def samples(self) -> int:
        """Grid length."""
        return int(self.x_m.size)

    @property
    def test(self) -> BoolArray:
        """Held-out samples that exist."""
        return self.present & ~self.train

    @property
    def duration_s(self) -> float:
        """Length of the grid, s."""
        return self.samples / self.rate_hz

    @cached_property
    def segments(self) -> Segments:
        """How multiple shooting cuts this trace (computed once per trace)."""
        return segment_trace(self)

    def with_fit_units(self, units: tuple[float, float] | None) -> Trace:
        """The same recording with a fit's units set; its segments are not cut again.

        They depend on the recording alone (0.2 s for four recordings, per further effect).
        """
        weighed = dataclasses.replace(self, fit_units=units)
        if "segments" in self.__dict__:
            weighed.__dict__["segments"] = self.__dict__["segments"]
        return weighed


def drive_phases(x_m: FloatArray, rate_hz: float) -> IntArray:
    """Phase of the drive at every sample: rise (x increasing: pulling), hold, fall, rest.

    The velocity is smoothed over 20 ms and "moving" means faster than 5 % of the peak
    speed (at least MOVING_SPEED_M_S), so encoder noise during holds is no motion.
    """
    v = np.gradient(x_m, 1.0 / rate_hz)
    width = max(1, int(0.02 * rate_hz))
    v = np.convolve(v, np.ones(width) / width, mode="same")
    threshold = max(MOVING_SPEED_M_S, 0.05 * float(np.abs(v).max()))
    top = x_m.max()
    low = x_m.min()
    high_level = x_m > low + 0.5 * (top - low)
    phase = np.where(high_level, PHASE_HOLD, PHASE_REST).astype(np.int64)
    phase[v > threshold] = PHASE_RISE
    phase[v < -threshold] = PHASE_FALL
    return phase


def cycle_index(x_m: FloatArray) -> IntArray:
    """Cycle number at every sample (−1 before the first).

    A cycle starts where x rises through 20 % of the stroke, after having been below
    10 % (hysteresis: noise near the threshold starts no cycle).
    """
    low, top = float(x_m.min()), float(x_m.max())
    up = low + 0.2 * (top - low)
    down = low + 0.1 * (top - low)
    cycle = np.full(x_m.size, -1, dtype=np.int64)
    armed = True
    k = -1
    start = 0
    for i in np.flatnonzero((x_m > up) | (x_m < down)):
        if x_m[i] > up and armed:
            cycle[start:i] = k
            k += 1
            start = int(i)
            armed = False
        elif x_m[i] < down:
            armed = True
    cycle[start:] = k
    return cycle


def _split(cycle: IntArray, n: int) -> BoolArray:
    """Interleave: even cycles (and the lead-in) train, odd cycles held out."""
    cycles = int(cycle.max()) + 1
    if cycles >= 2:
        train = (cycle < 0) | (cycle % 2 == 0)
        return np.asarray(train, dtype=bool)
    # One cycle or none: first half trains, second half is held out.
    train = np.zeros(n, dtype=bool)
    train[: n // 2] = True
    return train


def drive_cutoff_hz(x_m: FloatArray, rate_hz: float) -> float:
    """Where the drive's motion sinks below its encoder noise, Hz (the Nyquist: nowhere).

    The noise floor is the median Welch density at the top of the band; the cut-off is
    the upper edge of the highest band (log-spaced from 10 Hz) whose mean density is
    above twice the floor, i.e. where the motion's share still exceeds the noise's.
    """
    nyquist = rate_hz / 2
    if x_m.size < 64:
        return nyquist
    ramp = np.linspace(x_m[0], x_m[-1], x_m.size)  # the net move leaks into every band
    freq, density = welch(x_m - ramp, rate_hz, nperseg=min(1024, x_m.size), detrend=False)
    lo, hi = DRIVE_FLOOR_BAND
    floor = float(np.median(density[(freq >= lo * nyquist) & (freq <= hi * nyquist)]))
    octaves = np.log2(nyquist / 10.0)
    edges = np.geomspace(10.0, nyquist, max(2, int(np.ceil(octaves * DRIVE_BANDS_PER_OCTAVE))))
    cutoff = float(edges[0])
    for low, high in itertools.pairwise(edges):
        band = (freq >= low) & (freq < high)
        if band.any() and float(density[band].mean()) > 2.0 * floor:
            cutoff = float(high)
    return cutoff


def _smooth_drive(x_m: FloatArray, rate_hz: float) -> FloatArray:
    nyquist = rate_hz / 2
    cutoff = drive_cutoff_hz(x_m, rate_hz)
    if 0.8 * nyquist <= cutoff or x_m.size < 30:
        return x_m
    sos = butter(4, cutoff / nyquist, output="sos")
    # Pad with the end values so the filter starts and ends at rest.
    smoothed: FloatArray = sosfiltfilt(sos, x_m, padtype="constant")
    return smoothed


def make_trace(
    name: str,
    t_s: FloatArray,
    x_m: FloatArray,
    u_m: FloatArray,
    force_n: FloatArray,
    mass_kg: float,
) -> Trace:
    """Prepare one recording from its measured series (s, m, m, N; NaN where lost).

    ``name`` only labels messages and reports (the file name, for a recording).
    """
    try:
        run = align_arrays(t_s, x_m, u_m, force_n)
    except GridError as err:
        raise DiagnosisInputError(f"{name}: {err}") from None
    if run.t_s[-1] < MIN_DURATION_S:
        raise DiagnosisInputError(
            f"{name}: {run.t_s[-1]:.2f} s is too short to fit (need ≥ {MIN_DURATION_S:g} s)"
        )
    stroke = float(np.ptp(run.x_m))
    if stroke < MIN_STROKE_M:
        raise DiagnosisInputError(
            f"{name}: the drive moves only {stroke * 1e3:.3f} mm: a flat drive signal excites "
            "nothing to identify"
        )
    rest = run.rest_samples
    x_m = _smooth_drive(run.x_m, run.rate_hz)
    u_rest = np.nanmean(run.u_m[:rest]) if rest > 1 else run.u_m[np.isfinite(run.u_m)][0]
    u = run.u_m - u_rest
    noise_u = float(np.nanstd(run.u_m[:rest])) if rest > 10 else 0.0
    noise_f = float(np.nanstd(run.force_n[:rest])) if rest > 10 else 0.0
    phase = drive_phases(x_m, run.rate_hz)
    cycle = cycle_index(x_m)
    return Trace(
        name=name,
        rate_hz=run.rate_hz,
        mass_kg=mass_kg,
        x_m=x_m,
        u_m=u,
        force_n=run.force_n,
        present=run.present & np.isfinite(u) & np.isfinite(run.force_n),
        phase=phase,
        cycle=cycle,
        train=_split(cycle, run.x_m.size),
        noise_u_m=noise_u,
        noise_force_n=noise_f,
        stroke_m=stroke,
    )
