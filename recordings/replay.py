"""Replay a recording against the model, and compare two recordings.

The recording's measured drive position drives the baseline model; the simulated weight
displacement u and fibre force F are compared with the recorded ones per channel with the
paper's measures (sim.metrics). Channels:

* ``u`` — weight displacement, mm, both measured from their rest value before the motion;
* ``F`` — fibre force, N, absolute (the gauge reads the whole tension);
* ``F_dyn`` — dynamic force F − T₀, N, the paper's plotted quantity, each series minus its
  own rest force.

Dropped samples (gaps in the time base) are bridged for the model by linear
interpolation of x and left out of the comparison.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from sim.grid import AlignedRun, GridError, align_arrays
from sim.metrics import ChannelMetrics, channel_metrics
from sim.model import Model
from sim.params import StandParams

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
log = logging.getLogger(__name__)

__all__ = ["AlignedRun", "ReplayResult", "align", "compare_runs", "replay"]

CHANNELS = ("u", "F", "F_dyn")


class ReplayError(ValueError):
    """A recording that cannot be replayed (too short, no drive motion, no channel)."""


def align(frame: pd.DataFrame, rate_hz: float | None = None) -> AlignedRun:
    """Put a recording's x, u, F on a uniform grid (the recording's own rate)."""
    for column in ("x_mm", "u_mm", "F_N"):
        if column not in frame.columns:
            raise ReplayError(f"the recording has no {column} channel")
    try:
        return align_arrays(
            np.asarray(frame.index, dtype=np.float64),
            np.asarray(frame["x_mm"], dtype=np.float64) * 1e-3,
            np.asarray(frame["u_mm"], dtype=np.float64) * 1e-3,
            np.asarray(frame["F_N"], dtype=np.float64),
            rate_hz,
        )
    except GridError as err:
        raise ReplayError(str(err).replace("nothing to compare", "nothing to replay")) from None


def _rest_value(values: FloatArray, rest_samples: int) -> float:
    head = values[: max(rest_samples, 1)]
    head = head[np.isfinite(head)]
    if head.size == 0:
        finite = values[np.isfinite(values)]
        return float(finite[0]) if finite.size else 0.0
    return float(head.mean())


@dataclass(frozen=True)
class ReplayResult:
    """Recorded and simulated channels on one grid, and their metrics."""

    t_s: FloatArray
    x_mm: FloatArray
    recorded: dict[str, FloatArray]
    simulated: dict[str, FloatArray]
    metrics: dict[str, ChannelMetrics]
    present: BoolArray
    preload_tension_n: float
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: ``channels.<name>.{R, psi, nrmse, rms_error, samples}``."""
        return {
            "channels": {name: m.to_dict() for name, m in self.metrics.items()},
            "samples": int(self.t_s.size),
            "lost_samples": int(self.present.size - np.count_nonzero(self.present)),
            "preload_tension_n": self.preload_tension_n,
            "notes": list(self.notes),
        }


def _channels(u_m: FloatArray, force_n: FloatArray, rest: int) -> dict[str, FloatArray]:
    u_mm = (u_m - _rest_value(u_m, rest)) * 1e3
    return {"u": u_mm, "F": force_n, "F_dyn": force_n - _rest_value(force_n, rest)}


def _measure(
    recorded: dict[str, FloatArray], other: dict[str, FloatArray], present: BoolArray
) -> dict[str, ChannelMetrics]:
    return {
        name: channel_metrics(recorded[name][present], other[name][present]) for name in CHANNELS
    }


def replay(frame: pd.DataFrame, params: StandParams) -> ReplayResult:
    """Drive the model with the recording's x and compare u, F, F − T₀."""
    run = align(frame)
    sim = Model(params).run(run.x_m, run.rate_hz)
    recorded = _channels(run.u_m, run.force_n, run.rest_samples)
    simulated = {
        "u": sim.u_m * 1e3,
        "F": sim.force_n,
        "F_dyn": sim.force_n - params.preload_tension_n,
    }
    notes = []
    if run.lost_samples:
        notes.append(f"{run.lost_samples} lost sample(s) left out of the comparison")
    rest_force = _rest_value(run.force_n, run.rest_samples)
    if abs(rest_force - params.preload_tension_n) > 0.05 * params.preload_tension_n:
        notes.append(
            f"recorded rest force {rest_force:.2f} N differs from the model's "
            f"T0 = {params.preload_tension_n:.2f} N by more than 5 % (mass or gauge?)"
        )
    metrics = _measure(recorded, simulated, run.present)
    return ReplayResult(
        run.t_s,
        run.x_m * 1e3,
        recorded,
        simulated,
        metrics,
        run.present,
        params.preload_tension_n,
        notes,
    )


def compare_runs(frame_a: pd.DataFrame, frame_b: pd.DataFrame) -> ReplayResult:
    """Two recordings against each other (A is 'recorded', B the comparison), same measures."""
    a, b = align(frame_a), align(frame_b)
    if abs(a.rate_hz - b.rate_hz) > 1e-6 * a.rate_hz:
        raise ReplayError(f"sample rates differ: {a.rate_hz:g} Hz and {b.rate_hz:g} Hz")
    # Align on the start of the motion, then compare the common span.
    shift_a, shift_b = a.rest_samples, b.rest_samples
    lead = min(shift_a, shift_b)
    start_a, start_b = shift_a - lead, shift_b - lead
    n = min(a.t_s.size - start_a, b.t_s.size - start_b)
    sa, sb = slice(start_a, start_a + n), slice(start_b, start_b + n)
    rec = _channels(a.u_m[sa], a.force_n[sa], lead)
    oth = _channels(b.u_m[sb], b.force_n[sb], lead)
    present = a.present[sa] & b.present[sb]
    notes = [f"compared {n} samples from {lead} before the motion starts"]
    if a.t_s.size != b.t_s.size:
        notes.append(f"lengths differ ({a.t_s.size} and {b.t_s.size} samples)")
    return ReplayResult(
        a.t_s[:n],
        a.x_m[sa] * 1e3,
        rec,
        oth,
        _measure(rec, oth, present),
        present,
        _rest_value(a.force_n, a.rest_samples),
        notes,
    )
