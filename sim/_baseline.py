"""The baseline model of STAND.md §2 on its fast kernel (private: use ``sim.model.Model``).

``simulate`` runs one parameter set, ``simulate_rows`` many kernel rows at once on all
cores, ``simulate_segment_rows`` many short runs from given states, ``BaselineStream``
block by block. The compiled integrator lives in ``sim.kernel``; this module turns
StandParams into its flat arrays and back.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

from sim import kernel
from sim.errors import SimulationError
from sim.params import FrictionTable, StandParams
from sim.results import BatchResult, SimResult

FloatArray = NDArray[np.float64]

__all__ = [
    "DEFAULT_SUBSTEPS",
    "BaselineStream",
    "check_input",
    "friction_arrays",
    "param_vector",
    "simulate",
    "simulate_rows",
    "simulate_segment_rows",
]

#: RK4 steps per sample interval; 1 at 2 kHz meets the 0.1 % accuracy bound (see tests).
DEFAULT_SUBSTEPS = 1


def param_vector(params: StandParams) -> FloatArray:
    """The kernel's flat parameter row for one StandParams."""
    row = np.zeros(kernel.N_PARAMS)
    row[kernel.P_MASS] = params.mass_kg
    row[kernel.P_PROJ] = params.projection
    row[kernel.P_STIFF] = params.stiffness_n_m
    row[kernel.P_DAMP] = params.damping_n_s_m
    friction_n = params.normal_force_n * params.friction_scale if params.friction else 0.0
    row[kernel.P_FRICTION_N] = friction_n
    row[kernel.P_GRAVITY_N] = params.gravity_along_n
    row[kernel.P_PRELOAD] = params.preload_m
    row[kernel.P_VREG] = params.friction.v_reg_m_s if params.friction else 1e-3
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
    x = np.ascontiguousarray(x_m, dtype=np.float64)
    if x.ndim != 1 or x.shape[0] < 2:
        raise SimulationError(f"drive position must be a 1-D series of ≥ 2 samples, got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise SimulationError("All drive positions must be finite.")
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise SimulationError(f"sample rate must be > 0 Hz, got {rate_hz}")
    rel: FloatArray = x - x[0]  # the model starts at rest: x from the first sample
    return rel


def simulate(
    x_m: FloatArray, rate_hz: float, params: StandParams, substeps: int = DEFAULT_SUBSTEPS
) -> SimResult:
    """Simulate the weight and fibre for a drive position series.

    Parameters
    ----------
    x_m
        Drive position, m, downward positive, shape (N,), sampled at ``rate_hz``.
    rate_hz
        Sample rate, Hz.
    params
        The stand's parameters.
    substeps
        RK4 steps per sample interval.
    """
    x = check_input(x_m, rate_hz)
    n = x.shape[0]
    u, v, f = np.empty(n), np.empty(n), np.empty(n)
    knots, coef = friction_arrays(params.friction)
    kernel.simulate_into(x, 1.0 / rate_hz, substeps, param_vector(params), knots, coef, u, v, f)
    t = np.arange(n) / rate_hz
    return SimResult(t, np.asarray(x_m, dtype=np.float64), u, v, f, params.preload_tension_n)


def simulate_rows(
    x_rel_m: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    table: FrictionTable | None,
    substeps: int = DEFAULT_SUBSTEPS,
) -> BatchResult:
    """Lowest-level batch entry: kernel parameter rows (see ``param_vector``)."""
    x2 = np.ascontiguousarray(np.atleast_2d(x_rel_m), dtype=np.float64)
    sets, n = rows.shape[0], x2.shape[1]
    u, v, f = np.empty((sets, n)), np.empty((sets, n)), np.empty((sets, n))
    knots, coef = friction_arrays(table)
    kernel.simulate_batch_into(
        x2, 1.0 / rate_hz, substeps, np.ascontiguousarray(rows), knots, coef, u, v, f
    )
    return BatchResult(np.arange(n) / rate_hz, u, v, f, u, f)


class BaselineStream:
    """The baseline model advanced block by block, for a simulated stand in real time.

    Starts at static rest with the drive at ``x0_m``; each ``advance`` takes the drive
    positions of the next samples and returns the weight displacement and fibre force at
    them. Results equal one ``simulate`` call over the concatenated blocks.
    """

    def __init__(
        self,
        params: StandParams,
        rate_hz: float,
        x0_m: float = 0.0,
        substeps: int = DEFAULT_SUBSTEPS,
    ) -> None:
        self.params = params
        self.rate_hz = rate_hz
        self._row = param_vector(params)
        self._knots, self._coef = friction_arrays(params.friction)
        self._substeps = substeps
        self._x0 = x0_m
        self._last_x = x0_m
        self._state: tuple[float, float, bool] = (0.0, 0.0, True)

    @property
    def velocity_m_s(self) -> float:
        """Weight velocity after the last sample, m/s."""
        return self._state[1]

    def advance(self, x_m: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Weight displacement u (m) and fibre force F (N) at the next len(x_m) samples."""
        block = np.ascontiguousarray(x_m, dtype=np.float64)
        if block.ndim != 1 or not np.all(np.isfinite(block)):
            raise SimulationError("drive positions must be a finite 1-D block")
        x = np.empty(block.shape[0] + 1)
        x[0] = self._last_x
        x[1:] = block
        x -= self._x0
        n = x.shape[0]
        u, v, f = np.empty(n), np.empty(n), np.empty(n)
        u0, v0, taut0 = self._state
        self._state = kernel.advance_into(
            x,
            1.0 / self.rate_hz,
            self._substeps,
            self._row,
            self._knots,
            self._coef,
            u0,
            v0,
            taut0,
            u,
            v,
            f,
        )
        if block.shape[0]:
            self._last_x = float(block[-1])
        return u[1:], f[1:]


def simulate_segment_rows(
    x_rel_m: FloatArray,
    rate_hz: float,
    rows: FloatArray,
    table: FrictionTable | None,
    starts: NDArray[np.int64],
    lengths: NDArray[np.int64],
    init: FloatArray,
    substeps: int = DEFAULT_SUBSTEPS,
    serial: bool = False,
) -> tuple[FloatArray, FloatArray]:
    """Many short runs from given states (multiple shooting), all in one parallel batch.

    Parameters
    ----------
    x_rel_m
        Drive position relative to rest, m, shape (N,).
    rate_hz
        Sample rate, Hz.
    rows
        Kernel parameter rows (``param_vector``), shape (sets, N_PARAMS).
    table
        The friction table all rows share.
    starts, lengths
        First sample and number of samples of each segment, shape (segments,).
    init
        Start state (u m, v m/s) of each set's segment, shape (sets, segments, 2); a
        segment starting at sample 0 starts from static rest instead.
    substeps
        RK4 steps per sample interval.
    serial
        Run on the calling thread without the GIL (several traces side by side, one
        thread each) instead of on all cores.

    Returns
    -------
    u, force
        Weight displacement (m) and tension (N), shape (sets, segments, max length);
        each segment's last value is held to the end of its row.
    """
    rows2 = np.ascontiguousarray(np.atleast_2d(rows), dtype=np.float64)
    sets, segs, width = rows2.shape[0], starts.shape[0], int(lengths.max())
    u, f = np.empty((sets, segs, width)), np.empty((sets, segs, width))
    knots, coef = friction_arrays(table)
    run = kernel.simulate_segments_serial if serial else kernel.simulate_segments_into
    run(
        np.ascontiguousarray(x_rel_m, dtype=np.float64), 1.0 / rate_hz, substeps, rows2,
        knots, coef, np.ascontiguousarray(starts, dtype=np.int64),
        np.ascontiguousarray(lengths, dtype=np.int64),
        np.ascontiguousarray(init, dtype=np.float64), u, f,
    )  # fmt: skip
    return u, f
