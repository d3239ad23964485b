"""Segment starts refined by the model over a window of measurements (private: ``sim.model``).

A segment restarts from the weight's u and v estimated by a local cubic fit of the
recorded u (``sim.identify.shooting``). On a taut fibre the weight rings on it at
√(k/m), lightly damped, and a velocity error δv starts a ringing of δv/ω in u and
δv·√(k·m) in F that lasts the whole segment: on the check's recordings the true model,
restarted so, left up to 11× the noise held out where one open-loop run left 1.0–1.3,
and from the true v 1.0–1.25. A polynomial cannot do better (its window either lets in the
gauge noise or bends over the ringing); the model can, because it knows the ringing.

So every later segment's (u, v) is corrected by the recordings over a window after its
start (the segment's unscored warm-up): two more runs over the window, each from a start
moved a little in u or in v, give the channels' sensitivities; the correction is the
weighted least-squares one, with the local fit's estimate as a prior of its own spread
(the gauge noise, or the fit's residual where the cubic cannot follow the motion), held
within three of those spreads, so a window the linear picture does not fit (a stick, a
snatch, a force spike) moves the start little. Both gauges weigh in, each in its own
noise unit, so a form one of them has and the candidate lacks (a dial gauge's backlash,
a force gauge's drifting zero) moves the start only as far as the other allows; u's
prior is widened (``U_PRIOR_WIDENING``) so that on a taut fibre the force has its say
on u too. A channel recorded late has no prediction in its first samples (their true
values lie before the start): those weigh nothing; for one recorded early the window's
runs go on past it. The u reading is compared from where the row reads the start: a row
whose gauge scale is not the recordings' (a dial gauge's gain being tried) reads every
restart off by a level no start explains, and that level must not move the start.
The window lies before the segment's scored body, so its predictions stay predictions:
the start comes from measurements, never from a fitted trajectory. Runs there are not
chained (the carried states start quasi-static).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.params import FrictionTable
from sim.physics import layout, runs

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

__all__ = ["StartWindow", "refined_starts"]

#: The correction is held within this many of the prior's spreads.
HOLD_SPREADS = 3.0
#: u's prior spread is the local fit's this many times: the dial gauge reads the weight
#: only up to the form its candidate lacks (backlash, a curvature: tens of µm). With the
#: fit's own spread the other stand's dial gauge (18 µm of backlash) had a time skew
#: named beside it; widened, the check's restarts are as good or better (a heavy quick
#: recording: 1.50 → 1.00 noise units). Weighing the force alone where the fibre is taut
#: (the dial gauge only where slack) let a drifting force zero and a ringing load cell
#: into the starts instead.
U_PRIOR_WIDENING = 10.0
#: The starts are moved by this share of the prior's spread to get the sensitivities.
PROBE_SHARE = 0.1


@dataclass(frozen=True)
class StartWindow:
    """What refines the segment starts: the recorded channels after each, and their noise.

    Attributes
    ----------
    samples
        Window length after each start (at most the segment's run).
    u_m, force_n
        The recorded channels at every sample (lost ones bridged), m and N.
    present
        Which samples were recorded (the others weigh nothing).
    noise_u_m, noise_force_n
        The gauges' noise, m and N rms (the residuals' units).
    spread_u_m, spread_v_m_s
        The starting estimate's spread at every sample (the prior), recorded units.
    fit_u_m
        The local fit's u at every sample (what the starts come from), m.
    """

    samples: int
    u_m: FloatArray
    force_n: FloatArray
    present: BoolArray
    noise_u_m: float
    noise_force_n: float
    spread_u_m: FloatArray
    spread_v_m_s: FloatArray
    fit_u_m: FloatArray

    @property
    def usable(self) -> bool:
        """Both gauges have a noise unit (without, nothing says how far to trust them)."""
        return bool(self.samples > 1 and self.noise_u_m > 0 and self.noise_force_n > 0)


def refined_starts(
    x_rel_m: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    table: FrictionTable | None,
    starts: IntArray,
    lengths: IntArray,
    init: FloatArray,
    seats: FloatArray,
    window: StartWindow,
    scale: FloatArray,
    substeps: int,
    serial: bool,
) -> FloatArray:
    """``init`` (sets, segments, N_INIT) with every later segment's u and v refined.

    ``scale`` (sets,): each row's recorded-to-model factor of u (the dial gauge's G, as
    ``gauges.true_channels`` divides by it). Returns a new array; ``init`` is untouched.
    """
    later = np.flatnonzero(starts > 0)
    if not window.usable or later.size == 0:
        return init
    span = np.minimum(window.samples, lengths[later]).astype(np.int64)
    # A channel recorded early reads past the window: its runs go on that far.
    early = int(max(_late(rows, layout.R_CS_FORCE, rate_hz, -1.0).max(),
                    _late(rows, layout.R_CS_DISP, rate_hz, -1.0).max()))  # fmt: skip
    run = np.minimum(window.samples + early, x_rel_m.size - starts[later]).astype(np.int64)
    at = starts[later]
    prior_u = U_PRIOR_WIDENING * window.spread_u_m[at][None, :] / scale[:, None]  # model units
    prior_v = window.spread_v_m_s[at][None, :] / scale[:, None]
    known = (prior_u > 0) & (prior_v > 0) & np.isfinite(prior_u) & np.isfinite(prior_v)
    if not known.any():
        return init
    prior_u, prior_v = np.where(known, prior_u, 1.0), np.where(known, prior_v, 1.0)
    probe_u, probe_v = PROBE_SHARE * prior_u, PROBE_SHARE * prior_v
    probes = np.repeat(init[:, later], 3, axis=0)  # per row: as is, u moved, v moved
    probes[1::3, :, layout.I_U] += probe_u
    probes[2::3, :, layout.I_V] += probe_v
    u3, f3 = runs.simulate_segments(
        x_rel_m, rate_hz, np.repeat(rows, 3, axis=0), table, starts[later], run, probes,
        substeps, serial=serial, seats=np.repeat(seats, 3, axis=0),
    )  # fmt: skip
    width = f3.shape[2]
    idx = starts[later, None] + np.arange(width)[None, :]
    inside = np.arange(width)[None, :] < span[:, None]
    idx = np.minimum(idx, window.force_n.size - 1)
    weight = (inside & window.present[idx]).astype(np.float64)  # (segments, width)
    u0, f0 = u3[0::3], f3[0::3]
    jf = _sensitivities(f3, probe_u, probe_v) / window.noise_force_n  # (sets, seg, width, 2)
    ju = _sensitivities(u3, probe_u, probe_v) / window.noise_u_m
    rf = (window.force_n[idx][None] - f0) / window.noise_force_n
    # u against the row's own reading of the start (``_reading_jump``).
    jump = _reading_jump(window, u0, at, rows, rate_hz)
    ru = (window.u_m[idx][None] - u0 - jump) / window.noise_u_m
    offsets = np.arange(width)[None, None, :]
    wf = (weight[None] * (offsets >= _late(rows, layout.R_CS_FORCE, rate_hz)))[..., None]
    wu = (weight[None] * (offsets >= _late(rows, layout.R_CS_DISP, rate_hz)))[..., None]
    normal = np.einsum("bskp,bskq->bspq", jf * wf, jf) + np.einsum("bskp,bskq->bspq", ju * wu, ju)
    normal[..., 0, 0] += 1.0 / prior_u**2
    normal[..., 1, 1] += 1.0 / prior_v**2
    rhs = np.einsum("bskp,bsk->bsp", jf * wf, rf) + np.einsum("bskp,bsk->bsp", ju * wu, ru)
    ok = known & np.isfinite(normal).all(axis=(-1, -2)) & np.isfinite(rhs).all(axis=-1)
    normal[~ok], rhs[~ok] = np.eye(2), 0.0
    step = np.linalg.solve(normal, rhs[..., None])[..., 0]  # (sets, segments, 2)
    hold = HOLD_SPREADS * np.stack([prior_u, prior_v], axis=-1)
    step = np.where(ok[..., None], np.clip(step, -hold, hold), 0.0)
    out = init.copy()
    out[:, later, layout.I_U] += step[..., 0]
    out[:, later, layout.I_V] += step[..., 1]
    return out


def _reading_jump(
    window: StartWindow, u0: FloatArray, at: IntArray, rows: FloatArray, rate_hz: float
) -> FloatArray:
    """Per row and segment (sets, segments, 1): where the u reading starts off the fit's.

    A row whose reading of the start is not the recorded one (a dial gauge's gain other
    than the scale the recordings show, ``dial_slope``; the baseline without the gauge
    scale) reads every restart off by its scale's error times u, a constant over the
    window that no start explains: left in, it pulled u to the hold and bent v to meet
    it (a 0.8 % gain: 75 µm and 4 mm/s, and the gain's score test on top of a force
    gauge low-pass rose from 0 to 0.04 of the remainder). Read where the run's reading
    is a prediction (a late channel's first samples are held values); 0 where the row
    reads its start as recorded.
    """
    first = np.minimum(_late(rows, layout.R_CS_DISP, rate_hz)[:, 0, 0], u0.shape[2] - 1)
    start_reading = u0[np.arange(u0.shape[0]), :, first]  # (sets, segments)
    fitted = window.fit_u_m[np.minimum(at[None, :] + first[:, None], window.fit_u_m.size - 1)]
    return np.asarray((fitted - start_reading)[..., None], dtype=np.float64)


def _sensitivities(runs3: FloatArray, probe_u: FloatArray, probe_v: FloatArray) -> FloatArray:
    """d(channel)/du and d(channel)/dv from the runs as is, u moved and v moved."""
    base = runs3[0::3]
    by_u = (runs3[1::3] - base) / probe_u[..., None]
    by_v = (runs3[2::3] - base) / probe_v[..., None]
    return np.stack([by_u, by_v], axis=-1)


def _late(rows: FloatArray, column: int, rate_hz: float, sign: float = 1.0) -> IntArray:
    """Per row (sets, 1, 1): the samples a skewed channel is recorded late (sign −1: early).

    A run's first samples of a late channel are held values, not predictions (its true
    values lie before the start); an early one reads past the run's end.
    """
    on = rows[:, layout.R_CS_ON] > 0.0
    late = np.where(on, np.maximum(sign * rows[:, column], 0.0) * rate_hz, 0.0)
    # A whole number of samples stays itself whatever the rate's last digit (2 ms at
    # 1999.9999… Hz or at 2000 Hz: 4 samples).
    return np.ceil(late - 1e-6).astype(np.int64)[:, None, None]
