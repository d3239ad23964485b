"""What the gauges record, and back: the one chain of gauge effects (private: ``sim.model``).

Forward, true u and F → recorded: the built-in gauge effects in their physical order
(``sim.effects.measure``: the dial gauge's calibration, the force gauge's low-pass, then
the channels' skew), then the gauge effects added with ``register`` in the registry's
order (``EffectInfo.record``: memoryless, so a block-by-block stream and a whole run
agree). ``record`` does whole runs (from rest, batches, segments), ``GaugeStream`` the
same block by block. Backward (``true_channels``, for segment restarts): each inverse in
the reverse order (``EffectInfo.invert``, the built-in ``EffectInfo.true_channels``),
then the dial gauge's scale as the recording shows it. An added gauge effect plugs in
here and nowhere else.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import NDArray

from sim.effects import measure
from sim.effects.info import EffectInfo
from sim.effects.registry import EFFECTS, EffectError
from sim.physics import layout

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = ["GaugeStream", "record", "transform_key", "true_channels"]


def record(
    u: FloatArray,
    force: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    gauge0: FloatArray | None = None,
    first: IntArray | None = None,
    runs_per_row: int = 1,
) -> tuple[FloatArray, FloatArray]:
    """Recorded u (m) and F (N) of runs (runs, samples) with these kernel rows.

    ``gauge0`` (sets, 2): the force gauge's output and its rate at each run's first
    sample (NaN, or None for all: settled on the run's first force, a run from rest);
    ``first`` (sets,): each run's first sample in its recording (None: 0), the time
    base of added gauge effects; ``runs_per_row``: each row's consecutive runs (a row's
    segments). Returns ``u`` and ``force`` themselves if no row has a
    gauge effect on (the recorded channels are the true ones).
    """
    sets = u.shape[0]
    mrows = measure.measurement_rows(rows)
    added = _added_on(rows)
    if runs_per_row > 1:
        mrows = np.repeat(mrows, runs_per_row, axis=0)
    if not mrows[:, [measure.M_DG_ON, measure.M_FG_ON, measure.M_CS_ON]].any():
        if not added:
            return u, force
        rec_u, rec_f = u.copy(), force.copy()
    else:
        rec_u, rec_f = np.empty_like(u), np.empty_like(force)
        settled = np.full((sets, 2), np.nan) if gauge0 is None else gauge0
        measure.measure_batch_into(u, force, 1.0 / rate_hz, mrows, settled, rec_u, rec_f)
    starts = np.zeros(sets, dtype=np.int64) if first is None else first
    _record_added(added, rows, rate_hz, starts, rec_u, rec_f, runs_per_row)
    return rec_u, rec_f


def _added_on(rows: FloatArray) -> list[EffectInfo]:
    """The added gauge effects that some row has on, in the registry's order."""
    return [
        info
        for info in EFFECTS.values()
        if info.record is not None and np.any(rows[:, info.flag_column] > 0)
    ]


def _values(info: EffectInfo, row: FloatArray) -> FloatArray:
    return np.array([row[p.column] for p in info.params], dtype=np.float64)


def _record_added(
    added: Iterable[EffectInfo],
    rows: FloatArray,
    rate_hz: float,
    first: IntArray,
    u: FloatArray,
    force: FloatArray,
    runs_per_row: int = 1,
) -> None:
    """Apply the added gauge effects, in place, to each run whose row has them on."""
    n = u.shape[1]
    for info in added:
        assert info.record is not None
        for r in np.flatnonzero(rows[:, info.flag_column] > 0):
            values = _values(info, rows[r])
            for b in range(r * runs_per_row, (r + 1) * runs_per_row):
                t = (first[b] + np.arange(n)) / rate_hz
                u[b], force[b] = info.record(values, t, u[b], force[b])


def transform_key(row: FloatArray, on: list[EffectInfo]) -> bytes:
    """What ``true_channels`` depends on in a row.

    The gauge's scale and, for each effect with an inverse, its flag and parameters.
    """
    parts = [row[layout.P_PROJ]]
    for info in on:
        if info.true_channels is not None or info.invert is not None:
            parts += [float(info.flag_column)] + [row[p.column] for p in info.params]
    return np.asarray(parts, dtype=np.float64).tobytes()


def true_channels(
    row: FloatArray,
    on: list[EffectInfo],
    rate_hz: float,
    u_m: FloatArray,
    v_m_s: FloatArray,
    force_n: FloatArray,
    dial_slope: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The weight's u and v on the model's scale and the force, from the recorded ones.

    ``on``: the row's effects in the registry's order; the recorded channels from the
    recording's first sample.
    """
    u, v, force = u_m, v_m_s, force_n
    for info in reversed(on):  # the last stage of the chain first
        if info.invert is not None:
            t = np.arange(u.shape[0]) / rate_hz
            u, v, force = info.invert(_values(info, row), t, u, v, force)
        elif info.true_channels is not None:
            u, v, force = info.true_channels(row, rate_hz, u, v, force)
    if np.isfinite(dial_slope) and dial_slope > 0:
        scale = dial_slope * row[layout.P_PROJ]
        u, v = u / scale, v / scale
    return u, v, force


class GaugeStream:
    """``record`` block by block for one run from rest (the force at rest ``t0``, N)."""

    def __init__(self, row: FloatArray, rate_hz: float, t0: float) -> None:
        self._row = row
        self._rate = rate_hz
        self._m = measure.measurement_rows(row)[0]
        self._skews = (self._m[measure.M_SKEW_U], self._m[measure.M_SKEW_F])
        if self._m[measure.M_CS_ON] > 0 and min(self._skews) < 0:
            raise EffectError("a stream cannot record a channel early (negative skew)")
        self._gauge = np.array([t0, 0.0, t0])  # filter state (y, ẏ, previous input)
        u_rest = self._m[measure.M_OFFSET] if self._m[measure.M_DG_ON] > 0 else 0.0
        depth = int(np.ceil(max(self._skews) * rate_hz)) + 2
        self._hist_u = np.full(depth, u_rest)
        self._hist_f = np.full(depth, t0)
        self._added = _added_on(row[None, :])
        self._sample = 1  # the first block's first sample: sample 0 is the rest

    def __call__(self, u: FloatArray, force: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Recorded u (m) and F (N) of the next block of true ones."""
        rec_u, rec_f = self._builtin(u, force, 1.0 / self._rate)
        if self._added:
            rec_u, rec_f = rec_u[None, :].copy(), rec_f[None, :].copy()
            first = np.array([self._sample], dtype=np.int64)
            _record_added(self._added, self._row[None, :], self._rate, first, rec_u, rec_f)
            rec_u, rec_f = rec_u[0], rec_f[0]
        self._sample += u.shape[0]
        return rec_u, rec_f

    def _builtin(
        self, u: FloatArray, force: FloatArray, dt: float
    ) -> tuple[FloatArray, FloatArray]:
        m = self._m
        gu = (1.0 + m[measure.M_GAIN]) * u + m[measure.M_OFFSET] if m[measure.M_DG_ON] > 0 else u
        gf = force.copy()
        if m[measure.M_FG_ON] > 0:
            measure.gauge_filter_into(
                force, dt, m[measure.M_FC], m[measure.M_ZETA], self._gauge, gf
            )
        if m[measure.M_CS_ON] <= 0:
            return gu, gf
        out = []
        for hist, series, skew in (
            (self._hist_u, gu, self._skews[0]),
            (self._hist_f, gf, self._skews[1]),
        ):
            ext = np.concatenate([hist, series])
            rec = np.empty(series.shape[0])
            measure.skew_into(ext, hist.shape[0], skew / dt, rec)
            hist[:] = ext[ext.shape[0] - hist.shape[0] :]
            out.append(rec)
        return out[0], out[1]
