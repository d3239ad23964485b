"""Recordings a fitted model would make of itself: a bootstrap's replicates.

Two kinds. ``replicate_traces`` adds new white noise at each gauge's rest noise: what a
right model alone would leave, the held-out error that ``adequacy`` compares with.
``residual_replicates`` adds the errors the fit actually left, reweighted by a smooth
random process (a dependent wild bootstrap): what the estimator's bias and spread
(``intervals``) must see — errors that are larger in motion than at rest and
correlated over a stretch (a drive read with noise moves the outputs of a whole swing;
hum; a basin's misfit), which white noise at the rest level leaves out.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy.signal import fftconvolve

from sim.identify.fitting import Candidate, simulate_values
from sim.identify.heldout import BLOCK_S
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]

__all__ = ["reading_step", "replicate_traces", "residual_replicates", "smooth_weights"]

#: Steps between a quantised channel's readings are whole counts to this share of one.
ON_GRID = 1e-3


def replicate_traces(
    candidate: Candidate,
    values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
    rng: np.random.Generator,
    replicates: int,
) -> list[list[Trace]]:
    """Recordings the fitted model would make: its outputs plus each gauge's noise.

    The fitted model runs open loop on each recording's drive; every replicate adds new
    white noise at the recording's rest noise, reads it in the recording's own counts
    (``reading_step``), keeps its lost samples, cycles and the held-out split, and the
    campaign's dial gauge scale. The counts matter where the noise is below one: a dial
    gauge at rest that reads one count throughout has no rest noise, yet in motion its
    reading is off by up to half a count.
    """
    runs = _fitted_outputs(candidate, values, traces, nominal)
    out = []
    for _ in range(replicates):
        out.append([
            _read(tr, u + rng.normal(0.0, tr.noise_u_m, u.size),
                  f + rng.normal(0.0, tr.noise_force_n, f.size))
            for tr, (u, f) in zip(traces, runs, strict=True)
        ])  # fmt: skip
    return out


def residual_replicates(
    candidate: Candidate,
    values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
    rng: np.random.Generator,
    replicates: int,
    block_s: float = BLOCK_S,
) -> list[list[Trace]]:
    """Recordings of the fitted model with the fit's own errors, reweighted smoothly.

    A dependent wild bootstrap (Shao 2010): each replicate is the fitted model's outputs
    as the fit computes them (segments restarted from measured states) plus the
    recording's residuals times one random weight process (``smooth_weights``:
    mean 0, variance 1, correlated over ``block_s``, the held-out test's unit of
    independence), the same for u and F. It keeps the errors' size where they are large
    and their correlation within a stretch and between the channels, none of which the
    rest noise knows. The weights change smoothly: signs flipped per block put a jump of
    twice the residual at each block's edge, and a restart's velocity read across it
    (``shooting``) is off: on the dial gauge and gauge low-pass campaigns of seeds 6–8,
    8 of 54 intervals missed the truth with sign flips, 5 with smooth weights. Read in
    the recording's own counts as ``replicate_traces`` does.
    """
    # As the fit sees it: each segment restarted from the recording's measured state
    # (open loop, a light weight's quick swings drift apart by millimetres).
    runs = [tuple(run[0] for run in simulate_values(candidate, [values], tr, nominal))
            for tr in traces]  # fmt: skip
    out = []
    for _ in range(replicates):
        drawn = []
        for tr, (u, f) in zip(traces, runs, strict=True):
            weight = smooth_weights(rng, u.size, block_s * tr.rate_hz)
            res_u = np.nan_to_num(tr.u_m - u)  # a lost sample stays lost (``_read``)
            res_f = np.nan_to_num(tr.force_n - f)
            drawn.append(_read(tr, u + weight * res_u, f + weight * res_f))
        out.append(drawn)
    return out


def smooth_weights(rng: np.random.Generator, samples: int, span: float) -> FloatArray:
    """A stationary Gaussian process of mean 0 and variance 1, correlated over ``span``.

    White noise through a Gaussian kernel of σ = span/4 scaled to unit energy: its
    correlation is exp(−lag²/4σ²), 0.37 at half the span and 0.02 at the span.
    """
    sigma = max(span / 4.0, 1e-9)
    half = int(4.0 * sigma)
    kernel = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
    kernel /= np.linalg.norm(kernel)
    return np.asarray(fftconvolve(rng.normal(size=samples + 2 * half), kernel, mode="valid"))


def _fitted_outputs(
    candidate: Candidate, values: dict[str, float], traces: Sequence[Trace], nominal: StandParams
) -> list[tuple[FloatArray, FloatArray]]:
    """The fitted model's u (from its rest, as a trace counts it) and F, open loop on each drive."""
    runs = []
    for tr in traces:
        model = candidate.model(nominal, tr.mass_kg)
        res = model.run_batch(tr.x_m, tr.rate_hz, [candidate.variant(nominal, values)])
        runs.append((res.u_m[0] - res.u_m[0, 0], res.force_n[0]))
    return runs


def _read(trace: Trace, u: FloatArray, force: FloatArray) -> Trace:
    """``trace`` with these outputs, read in its own counts, lost where it lost samples."""
    u_r = _counts(u, reading_step(trace.u_m))
    f_r = _counts(force, reading_step(trace.force_n))
    return dataclasses.replace(
        trace,
        u_m=np.where(trace.present, u_r, np.nan),
        force_n=np.where(trace.present, f_r, np.nan),
    )


def reading_step(values: FloatArray) -> float:
    """A quantised channel's count (the least step between its readings), 0 if it has none.

    A channel is quantised when every step between its successive readings is a whole
    number of its least non-zero step (to ``ON_GRID``); a channel in floating point
    (an already scaled or filtered one) has steps of every size.
    """
    diffs = np.abs(np.diff(values[np.isfinite(values)]))
    moves = diffs[diffs > 0.0]
    if moves.size < 2:
        return 0.0
    step = float(moves.min())
    if step < 1e-9 * float(moves.max()):
        return 0.0
    counts = moves / step
    return step if bool(np.all(np.abs(counts - np.round(counts)) <= ON_GRID * counts)) else 0.0


def _counts(values: FloatArray, step: float) -> FloatArray:
    return np.round(values / step) * step if step > 0.0 else values
