"""The model's runs: rows, one run, batches, segments, a stream (private: ``sim.model``).

``simulate`` runs one stand with a list of effects, ``simulate_rows`` parameter rows
(built by ``parameter_row``), ``simulate_segments`` many short runs from measured
states, and ``Stream`` advances block by block for the simulated stand. Every run goes
through one compiled model (``sim.physics.compose``): without physical effects the
empty set of terms (the baseline), with them the built-in union (composed with the
forces and terms of effects added by ``register``); gauge effects then act on the
outputs, in one chain (``sim.physics.gauges``).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from types import ModuleType

import numpy as np
from numpy.typing import NDArray

from sim.effects.registry import EFFECTS, EffectError, EffectSpec, check_unique, effect_info
from sim.errors import SimulationError
from sim.params import FrictionTable, StandParams
from sim.physics import compose, gauges, layout
from sim.physics.lanes import in_serial_lane, stop_if_asked
from sim.results import BatchResult, ModelRun

FloatArray = NDArray[np.float64]

__all__ = [
    "DEFAULT_SUBSTEPS",
    "Stream",
    "check_input",
    "parameter_row",
    "simulate",
    "simulate_rows",
    "simulate_segments",
]

#: RK4 steps per sample interval; 1 at 2 kHz meets the 0.1 % accuracy bound (see tests).
DEFAULT_SUBSTEPS = 1


def param_vector(params: StandParams) -> FloatArray:
    """The baseline's eight parameters, the first columns of a row (``layout.P_*``)."""
    row = np.zeros(layout.R_DRIVE_SPAN)
    row[layout.P_MASS] = params.mass_kg
    row[layout.P_PROJ] = params.projection
    row[layout.P_STIFF] = params.stiffness_n_m
    row[layout.P_DAMP] = params.damping_n_s_m
    friction_n = params.normal_force_n * params.friction_scale if params.friction else 0.0
    row[layout.P_FRICTION_N] = friction_n
    row[layout.P_GRAVITY_N] = params.gravity_along_n
    row[layout.P_PRELOAD] = params.preload_m
    row[layout.P_VREG] = params.friction.v_reg_m_s if params.friction else 1e-3
    return row


def friction_arrays(table: FrictionTable | None) -> tuple[FloatArray, FloatArray]:
    """PCHIP knots and cubic coefficients (4, segments) of μ(v) for the kernel (copies)."""
    if table is None:
        return np.array([0.0, 1.0]), np.zeros((4, 1))  # μ ≡ 0
    knots, coef = _pchip_arrays(table)
    return knots.copy(), coef.copy()


@functools.lru_cache(maxsize=64)
def _pchip_arrays(table: FrictionTable) -> tuple[FloatArray, FloatArray]:
    # A fit simulates one table thousands of times (the friction scale multiplies the
    # normal force, not μ); scipy's PCHIP set-up cost more than a short segment's run.
    pchip = table.pchip()
    return np.asarray(pchip.x, dtype=np.float64), np.ascontiguousarray(pchip.c, dtype=np.float64)


def check_input(x_m: FloatArray, rate_hz: float) -> FloatArray:
    """The drive positions relative to the first (the model starts at rest there), checked."""
    x = np.ascontiguousarray(x_m, dtype=np.float64)
    if x.ndim != 1 or x.shape[0] < 2:
        raise SimulationError(f"drive position must be a 1-D series of ≥ 2 samples, got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise SimulationError("All drive positions must be finite.")
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise SimulationError(f"sample rate must be > 0 Hz, got {rate_hz}")
    rel: FloatArray = x - x[0]
    return rel


def parameter_row(stand: StandParams, effects: Sequence[EffectSpec] = ()) -> FloatArray:
    """The kernel's parameter row for a stand and its effects (checked)."""
    check_unique(effects)
    row = np.zeros(layout.N_ROW)
    row[: layout.R_DRIVE_SPAN] = param_vector(stand)
    row[layout.R_DRIVE_SPAN] = stand.drive_span_m
    row[layout.R_FREE_SPAN] = stand.free_length_m
    row[layout.R_FIBRE_LEN] = stand.fibre_length_m
    row[layout.R_LIN_DENSITY] = stand.linear_density_kg_m
    sin_beta = stand.lateral_offset_m / stand.free_length_m
    row[layout.R_SIN_BETA] = sin_beta
    # The weight span leaves the weight along the guide (up the incline, share n = cos β)
    # and sideways (sin β, horizontal): its vertical share is cos β·sin α.
    vertical = stand.projection * np.sin(np.radians(stand.incline_deg))
    row[layout.R_G_PERP_WEIGHT_SPAN] = stand.gravity_m_s2 * np.sqrt(1.0 - vertical**2)
    row[layout.R_GRAVITY] = stand.gravity_m_s2
    row[layout.R_SIN_HALF_WRAP] = np.sin(np.radians(stand.wrap_angle_deg) / 2)
    row[layout.R_RADIUS] = stand.pulley_radius_m
    for spec in effects:
        info = effect_info(spec.name)
        if info.check_stand is not None:
            info.check_stand(stand)
        row[info.flag_column] = 1.0
        if info.composed:  # an added gauge effect leaves the dynamics alone
            row[layout.R_X_ON] = 1.0
        values = spec.resolved()
        for p in info.params:
            row[p.column] = values[p.name]
    return row


def _kernel(rows: FloatArray) -> ModuleType:
    """The compiled model for these rows: the baseline unless one has a physical effect on.

    With one, the union of the built-in terms, composed with the added effects (forces,
    terms) that any row has on.
    """
    rows2 = np.atleast_2d(rows)
    physical = [info.flag_column for info in EFFECTS.values() if info.kind == "physical"]
    if not np.any(rows2[:, physical] > 0):
        return compose.baseline()
    added = tuple(
        info
        for info in EFFECTS.values()
        if info.composed and np.any(rows2[:, info.flag_column] > 0)
    )
    return compose.kernel_for(layout.TERMS, added)


def simulate(
    x_m: FloatArray,
    rate_hz: float,
    stand: StandParams,
    effects: Sequence[EffectSpec] = (),
    substeps: int = DEFAULT_SUBSTEPS,
) -> ModelRun:
    """Simulate the stand with effects for a drive position series.

    Parameters
    ----------
    x_m
        Drive position, m, downward positive, shape (N,), sampled at ``rate_hz``.
    rate_hz
        Sample rate, Hz.
    stand
        The stand's parameters.
    effects
        Effects switched on (each at most once); parameters not given take defaults.
    substeps
        Least RK4 steps per sample interval (stiff effects take more as needed).
    """
    x = check_input(x_m, rate_hz)
    n = x.shape[0]
    row = parameter_row(stand, effects)
    knots, coef = friction_arrays(stand.friction)
    u, v, t1, t2 = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    most = _kernel(row).simulate_into(x, 1.0 / rate_hz, substeps, row, knots, coef, u, v, t1, t2)
    rec_u, rec_f = gauges.record(u[None, :], t1[None, :], rate_hz, row[None, :])
    rec_u, rec_f = rec_u[0].copy(), rec_f[0].copy()  # apart from the true channels
    t = np.arange(n) / rate_hz
    x_out = np.asarray(x_m, dtype=np.float64)
    t0 = stand.preload_tension_n
    return ModelRun(t, x_out, rec_u, v, rec_f, t0, u, t1, t2, int(most))


def simulate_rows(
    x_rel_m: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    table: FrictionTable | None,
    substeps: int = DEFAULT_SUBSTEPS,
) -> BatchResult:
    """Lowest-level batch entry: kernel rows (``parameter_row``), drive relative to rest.

    ``x_rel_m`` is (N,) shared by all rows or (rows, N); all rows share one friction table.
    """
    x2 = np.ascontiguousarray(np.atleast_2d(x_rel_m), dtype=np.float64)
    rows2 = np.ascontiguousarray(np.atleast_2d(rows), dtype=np.float64)
    sets, n = rows2.shape[0], x2.shape[1]
    if x2.shape[0] not in (1, sets):
        raise EffectError(f"drive rows ({x2.shape[0]}) must be 1 or one per set ({sets})")
    kernel = _kernel(rows2)
    u, v, t1 = np.empty((sets, n)), np.empty((sets, n)), np.empty((sets, n))
    # With one segment the weight side's tension is the drive side's: the runner writes
    # the same value twice into one array (256 sets of a 60 s run: 250 MB less to touch,
    # 9 % of the batch's time).
    t2 = t1 if kernel.SEGMENTS < 2 else np.empty((sets, n))
    knots, coef = friction_arrays(table)
    dt = 1.0 / rate_hz
    kernel.simulate_batch_into(x2, dt, substeps, rows2, knots, coef, u, v, t1, t2)
    t = np.arange(n) / rate_hz
    rec_u, rec_f = gauges.record(u, t1, rate_hz, rows2)  # u, t1 themselves if no gauge is on
    return BatchResult(t, rec_u, v, rec_f, u, t1)


def measure_segments(
    u: FloatArray,
    force: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    starts: NDArray[np.int64],
    init: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Recorded u (m), F (N) of segment runs (sets, segments, samples).

    Each segment's run is measured on its own; a skewed channel is held beyond its ends.
    The force gauge's filter starts where the recording shows it (``init``'s recorded
    force and its rate; settled on the first force for a run from rest at sample 0):
    settled on the model's force instead, a 20 Hz gauge had not caught up by the end of
    the warm-up, and the true model's restarts cost 25× the open-loop error.
    """
    sets, segs, width = u.shape
    gauge0 = np.ascontiguousarray(init[:, :, [layout.I_F, layout.I_FRATE]], dtype=np.float64)
    gauge0[:, starts == 0, :] = np.nan
    flat_u = np.ascontiguousarray(u.reshape(sets * segs, width))
    flat_f = np.ascontiguousarray(force.reshape(sets * segs, width))
    rec_u, rec_f = gauges.record(
        flat_u, flat_f, rate_hz, np.atleast_2d(rows), gauge0.reshape(sets * segs, 2),
        np.tile(np.asarray(starts, dtype=np.int64), sets), runs_per_row=segs,
    )  # fmt: skip
    return rec_u.reshape(u.shape), rec_f.reshape(force.shape)


def simulate_segments(
    x_rel_m: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    table: FrictionTable | None,
    starts: NDArray[np.int64],
    lengths: NDArray[np.int64],
    init: FloatArray,
    substeps: int = DEFAULT_SUBSTEPS,
    chained: bool = False,
    serial: bool = False,
    seats: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Multiple shooting: many short runs of many rows from measured states, in parallel.

    ``init`` (sets, segments, ``layout.N_INIT``) holds each segment's measured start (u m,
    v m/s, F N, high-passed elongation m; see the kernel's ``measured_state`` for how the effects'
    own states are set from it); a segment starting at sample 0 starts from static rest;
    string modes, bristles and the pulley seat carry over from the previous segment's
    run when ``chained``. Returns the *recorded* u (m) and F (N), shape (sets, segments,
    max length), each segment measured on its own (``measure_segments``), last value
    held past its end. ``serial``: on the calling thread, without the GIL (several
    traces side by side) instead of on all cores. ``seats`` (sets, samples): the pulley
    seat's offset each row's runs hold at every sample, as the recorded slack episodes
    put it (``starts.start_states``); None: the model's own slack moves it.
    """
    stop_if_asked()  # a lane whose caller gave up ends here, between runs
    rows2 = np.ascontiguousarray(np.atleast_2d(rows), dtype=np.float64)
    sets, segs, width = rows2.shape[0], starts.shape[0], int(lengths.max())
    u, t1 = np.empty((sets, segs, width)), np.empty((sets, segs, width))
    knots, coef = friction_arrays(table)
    # ``chained``: string modes, bristles and the pulley seat carry over between
    # segments (see simulate_chained_into); the model decides.
    k = _kernel(rows2)
    if serial or in_serial_lane():
        kernel = k.simulate_chained_serial if chained else k.simulate_segments_serial
    else:
        kernel = k.simulate_chained_into if chained else k.simulate_segments_into
    kernel(
        np.ascontiguousarray(x_rel_m, dtype=np.float64), 1.0 / rate_hz, substeps, rows2,
        knots, coef, np.ascontiguousarray(starts, dtype=np.int64),
        np.ascontiguousarray(lengths, dtype=np.int64),
        np.ascontiguousarray(init, dtype=np.float64), u, t1,
        np.zeros((sets, 0)) if seats is None else np.ascontiguousarray(seats, dtype=np.float64),
    )  # fmt: skip
    return measure_segments(u, t1, rate_hz, rows2, starts, init)


class Stream:
    """The model advanced block by block (for the simulated stand).

    Starts at static rest with the drive at ``x0_m``; each ``advance`` takes the drive
    positions of the next samples and returns the *recorded* u (m) and F (N) at them,
    equal to one ``simulate`` call over the concatenated blocks. A stream
    cannot look ahead, so a negative channel skew (a channel recorded early) is refused.
    """

    def __init__(
        self,
        stand: StandParams,
        rate_hz: float,
        effects: Sequence[EffectSpec] = (),
        x0_m: float = 0.0,
        substeps: int = DEFAULT_SUBSTEPS,
    ) -> None:
        if not (np.isfinite(rate_hz) and rate_hz > 0):
            raise EffectError(f"sample rate must be > 0 Hz, got {rate_hz}")
        self.stand = stand
        self.rate_hz = rate_hz
        self.effects = tuple(effects)
        self._row = parameter_row(stand, effects)
        knots, coef = friction_arrays(stand.friction)
        self._kernel = _kernel(self._row)
        self._c = self._kernel.pack(self._row, knots, coef)
        self._y = np.array(self._kernel.rest_state(self._c), dtype=np.float64)
        self._substeps = substeps
        self._x0 = x0_m
        self._last_x = x0_m
        t0 = self._c[layout.D_K1] * self._c[layout.D_D10]  # the force at sample 0, as simulate_into
        self._measure = gauges.GaugeStream(self._row, rate_hz, t0)

    @property
    def velocity_m_s(self) -> float:
        """Weight velocity after the last sample, m/s."""
        return float(self._y[1])  # v: the second state in every set

    def advance(self, x_block_m: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Recorded weight displacement u (m) and force F (N) at the next samples."""
        block = np.ascontiguousarray(x_block_m, dtype=np.float64)
        if block.ndim != 1 or not np.all(np.isfinite(block)):
            raise EffectError("drive positions must be a finite 1-D block")
        n = block.shape[0]
        x = np.empty(n + 1)
        x[0] = self._last_x
        x[1:] = block
        x -= self._x0
        u, v, t1, t2 = (np.empty(n + 1) for _ in range(4))
        dt = 1.0 / self.rate_hz
        self._kernel.advance_into(x, dt, self._substeps, self._c, self._y, u, v, t1, t2)
        if n:
            self._last_x = float(block[-1])
        return self._measure(u[1:], t1[1:])
