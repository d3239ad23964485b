"""Segment starts refined by the model over a window of measurements (private: ``sim.model``).

A segment restarts from the weight's u and v estimated by a local polynomial fit of the
recorded u (``sim.identify.shooting``). On a taut fibre the weight rings on it at
√(k/m), lightly damped, and a velocity error δv starts a ringing of δv/ω in u and
δv·√(k·m) in F that lasts the whole segment: on the check's recordings the true model,
restarted so, left 1.3–11× the noise held out where one open-loop run left 1.0–1.1, and
from the true v 1.0–1.25. The polynomial cannot do better (its window either lets in the
gauge noise or bends over the ringing); the model can, because it knows the ringing.

So every later segment's (u, v) is corrected by the measurements of a window after its
start (the segment's unscored warm-up): two more runs over the window, each from a start
moved a little in u or in v, give the recorded channels' sensitivities; the correction
is the weighted least-squares one (u and F, each in its own noise unit) with the
polynomial estimate as a prior of its own noise spread, and it is held within three of
those spreads, so a window the linear picture does not fit (a stick, a snatch, a force
spike) moves the start little. The window lies before the segment's scored body, so its
predictions stay predictions: the start comes from measurements, never from a fitted
trajectory. Runs there are not chained (the carried states start quasi-static).
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
        The starting estimate's spread from the gauge noise (the prior), recorded units.
    """

    samples: int
    u_m: FloatArray
    force_n: FloatArray
    present: BoolArray
    noise_u_m: float
    noise_force_n: float
    spread_u_m: float
    spread_v_m_s: float

    @property
    def usable(self) -> bool:
        """Both channels carry noise (a noiseless recording needs no refinement)."""
        return bool(
            self.samples > 1
            and self.noise_u_m > 0
            and self.noise_force_n > 0
            and self.spread_u_m > 0
            and self.spread_v_m_s > 0
        )


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
    prior_u = window.spread_u_m / scale  # (sets,) in the model's units
    prior_v = window.spread_v_m_s / scale
    probe_u, probe_v = PROBE_SHARE * prior_u, PROBE_SHARE * prior_v
    probes = np.repeat(init[:, later], 3, axis=0)  # per row: as is, u moved, v moved
    probes[1::3, :, layout.I_U] += probe_u[:, None]
    probes[2::3, :, layout.I_V] += probe_v[:, None]
    u3, f3 = runs.simulate_segments(
        x_rel_m, rate_hz, np.repeat(rows, 3, axis=0), table, starts[later], span, probes,
        substeps, serial=serial, seats=np.repeat(seats, 3, axis=0),
    )  # fmt: skip
    width = u3.shape[2]
    idx = starts[later, None] + np.arange(width)[None, :]
    inside = np.arange(width)[None, :] < span[:, None]
    idx = np.minimum(idx, window.u_m.size - 1)
    weight = (inside & window.present[idx]).astype(np.float64)  # (segments, width)
    u0, f0 = u3[0::3], f3[0::3]
    ju = _sensitivities(u3, probe_u, probe_v) / window.noise_u_m  # (sets, segments, width, 2)
    jf = _sensitivities(f3, probe_u, probe_v) / window.noise_force_n
    ru = (window.u_m[idx][None] - u0) / window.noise_u_m
    rf = (window.force_n[idx][None] - f0) / window.noise_force_n
    w = weight[None, :, :, None]
    normal = np.einsum("bskp,bskq->bspq", ju * w, ju) + np.einsum("bskp,bskq->bspq", jf * w, jf)
    normal[..., 0, 0] += (1.0 / prior_u**2)[:, None]
    normal[..., 1, 1] += (1.0 / prior_v**2)[:, None]
    rhs = np.einsum("bskp,bsk->bsp", ju * w, ru) + np.einsum("bskp,bsk->bsp", jf * w, rf)
    ok = np.isfinite(normal).all(axis=(-1, -2)) & np.isfinite(rhs).all(axis=-1)
    normal[~ok], rhs[~ok] = np.eye(2), 0.0
    step = np.linalg.solve(normal, rhs[..., None])[..., 0]  # (sets, segments, 2)
    hold = HOLD_SPREADS * np.stack([prior_u, prior_v], axis=-1)[:, None, :]
    step = np.clip(step, -hold, hold)
    out = init.copy()
    out[:, later, layout.I_U] += step[..., 0]
    out[:, later, layout.I_V] += step[..., 1]
    return out


def _sensitivities(runs3: FloatArray, probe_u: FloatArray, probe_v: FloatArray) -> FloatArray:
    """d(channel)/du and d(channel)/dv from the runs as is, u moved and v moved."""
    base = runs3[0::3]
    by_u = (runs3[1::3] - base) / probe_u[:, None, None]
    by_v = (runs3[2::3] - base) / probe_v[:, None, None]
    return np.stack([by_u, by_v], axis=-1)
