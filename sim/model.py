"""The one front door to the stand's model: a stand, the effects switched on, and its runs.

``Model(stand, effects)`` is how everything outside the model runs it — ``simulate``,
replay, the simulated stand's gauges and the diagnosis alike::

    model = Model(stand, [EffectSpec("fibre_viscoelastic", {"relaxation_time_s": 0.02})])
    run = model.run(x_m, rate_hz)                        # one run from static rest
    batch = model.run_batch(x_m, rate_hz, variants)      # many parameter sets at once
    u, f = model.run_segments(x_m, rate_hz, restarts, variants)  # multiple shooting
    stream = model.stream(rate_hz)                       # block by block, in real time

The model alone decides how: every run goes through one compiled model
(``sim.physics``) composed for its terms — none without physical effects (the
baseline), else the built-in union with the forces of effects added by ``register`` —
and measurement effects (gauge calibration, skew, gauge dynamics) then transform the
outputs. Segment runs restart from measured channels: the model inverts its own gauge
effects to get the true state, sets the effects' states from the measurements, and
carries over from the previous segment the states the gauges cannot see (string modes,
LuGre bristle). The kernels are private to ``sim`` (an import-linter contract).

Variants name the parameters they change: a ``StandParams`` field (``stiffness_n_m``,
``damping_n_s_m``, ``friction_scale``, ``mass_kg``, ...) or ``"<effect>.<param>"`` of an
effect the model has.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from sim.effects.registry import EFFECTS, EffectError, EffectSpec, check_unique
from sim.errors import SimulationError
from sim.params import StandParams
from sim.physics import layout, runs, starts
from sim.physics.lanes import LaneStoppedError, in_serial_lane, serial_lane
from sim.physics.refine import StartWindow, refined_starts
from sim.physics.runs import DEFAULT_SUBSTEPS, check_input
from sim.results import BatchResult, ModelRun, SimResult

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = [
    "DEFAULT_SUBSTEPS",
    "BatchResult",
    "LaneStoppedError",
    "Model",
    "ModelRun",
    "ModelStream",
    "Restarts",
    "SimResult",
    "SimulationError",
    "StartWindow",
    "Variant",
    "in_serial_lane",
    "serial_lane",
]

#: Parameter changes of one set of a batch: StandParams field or "<effect>.<param>" → value.
Variant = Mapping[str, float]

_STAND_FIELDS = frozenset(f.name for f in fields(StandParams))


class ModelStream(Protocol):
    """The model advanced block by block (the simulated stand's physics)."""

    @property
    def velocity_m_s(self) -> float:
        """Weight velocity after the last sample, m/s."""
        ...

    def advance(self, x_m: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Recorded u (m) and F (N) at the next len(x_m) drive positions."""
        ...


@dataclass(frozen=True)
class Restarts:
    """Where the runs of a multiple-shooting simulation start, and what was measured.

    Attributes
    ----------
    starts, lengths
        First sample and number of samples of each segment run.
    u_m, v_m_s, force_n
        The recorded channels at every sample (smoothed): u (m), its rate (m/s), F (N).
        A segment starting at sample 0 starts from static rest instead.
    dial_slope
        How far the recorded u moves per metre of drive at constant force on a calm taut
        fibre (NaN: unknown). With the model's projection n it gives the displacement
        gauge's scale G = slope·n; every segment restarts from u/G, so a gauge's scale
        error stays in the u channel (the model's gauge effect then maps u to the
        reading) instead of becoming a wrong elongation, a wrong force.
    window
        The recorded channels after each start and their noise: each later segment's u
        and v are refined by the model over that window (``sim.physics.refine``); None:
        they start as estimated.
    """

    starts: IntArray
    lengths: IntArray
    u_m: FloatArray
    v_m_s: FloatArray
    force_n: FloatArray
    dial_slope: float = float("nan")
    window: StartWindow | None = None


class Model:
    """The baseline model of STAND.md §2 plus the effects of §5 switched on.

    Parameters
    ----------
    stand
        The stand's parameters.
    effects
        Effects switched on (each at most once); parameters not given take defaults.
    substeps
        Least RK4 steps per sample interval (stiff effects take more as needed).

    Raises
    ------
    EffectError
        An effect named twice, or a parameter outside its admissible range.
    """

    def __init__(
        self,
        stand: StandParams,
        effects: Sequence[EffectSpec] = (),
        substeps: int = DEFAULT_SUBSTEPS,
    ) -> None:
        check_unique(effects)
        for spec in effects:
            spec.resolved()  # refuses unknown names and values out of range, here
        self.stand = stand
        self.effects = tuple(effects)
        self.substeps = substeps
        kinds = {EFFECTS[e.name].kind for e in self.effects}
        #: Physical effects change the dynamics: the union of the built-in terms runs.
        self.physical = "physical" in kinds
        #: Measurement effects transform the outputs.
        self.measured = "measurement" in kinds
        #: Effects whose states the gauges cannot see carry them from segment to segment
        #: (``run_segments``): then every segment depends on the ones before it.
        self.chained = any(EFFECTS[e.name].carried for e in self.effects)

    def __repr__(self) -> str:
        names = ", ".join(str(e) for e in self.effects) or "baseline"
        return f"Model({names}, m = {self.stand.mass_kg:g} kg)"

    # -- parameter sets -------------------------------------------------------------
    def variant(self, values: Variant) -> Model:
        """The same model with some parameters changed (see the module docstring for names)."""
        stand_changes: dict[str, float] = {}
        effect_changes: dict[str, dict[str, float]] = {}
        for key, value in values.items():
            effect, dot, param = key.partition(".")
            if not dot:
                if key not in _STAND_FIELDS:
                    raise SimulationError(f"unknown stand parameter {key!r}")
                stand_changes[key] = float(value)
                continue
            if effect not in {e.name for e in self.effects}:
                raise EffectError(f"{key}: the model has no effect {effect!r}")
            effect_changes.setdefault(effect, {})[param] = float(value)
        effects = [
            EffectSpec(e.name, {**e.params, **effect_changes.get(e.name, {})}) for e in self.effects
        ]
        stand = self.stand.with_(**stand_changes) if stand_changes else self.stand
        return Model(stand, effects, self.substeps)

    def _rows(self, variants: Sequence[Variant]) -> FloatArray:
        """The kernel's parameter rows of the variants (``runs.parameter_row``)."""
        models = [self.variant(v) if v else self for v in variants]
        tables = {m.stand.friction for m in models}
        if len(tables) > 1:
            raise SimulationError("a batch must share one friction table (vary friction_scale)")
        return np.stack([runs.parameter_row(m.stand, m.effects) for m in models])

    # -- runs -----------------------------------------------------------------------
    def run(self, x_m: FloatArray, rate_hz: float) -> ModelRun:
        """One run from static rest over a drive position series (m, downward positive).

        Returns the recorded u and F (after the gauge effects) and the true channels.
        """
        return runs.simulate(x_m, rate_hz, self.stand, self.effects, self.substeps)

    def run_batch(
        self, x_m: FloatArray, rate_hz: float, variants: Sequence[Variant] = ({},)
    ) -> BatchResult:
        """Many parameter sets from static rest, in parallel on all cores.

        ``x_m`` is one drive series (N,) shared by all sets or one per set (sets, N).
        """
        x = np.asarray(x_m, dtype=np.float64)
        rel = (
            check_input(x, rate_hz)
            if x.ndim == 1
            else np.stack([check_input(row, rate_hz) for row in x])
        )
        if x.ndim == 2 and x.shape[0] not in (1, len(variants)):
            raise SimulationError(
                f"drive rows ({x.shape[0]}) must be 1 or one per set ({len(variants)})"
            )
        rows = self._rows(variants)
        return runs.simulate_rows(rel, rate_hz, rows, self.stand.friction, self.substeps)

    def run_segments(
        self,
        x_m: FloatArray,
        rate_hz: float,
        restarts: Restarts,
        variants: Sequence[Variant] = ({},),
        serial: bool = False,
    ) -> tuple[FloatArray, FloatArray]:
        """Multiple shooting: short runs restarted from measured states, in parallel.

        Returns the recorded u (m) and F (N) of every segment run, shape (sets,
        segments, longest segment), each segment's last value held past its end.
        ``serial``: the runs on the calling thread, without the GIL, so that several
        traces can run side by side (one thread each) instead of each on all cores.
        """
        x_rel = check_input(x_m, rate_hz)
        rows = self._rows(variants)
        init, seats = starts.start_states(
            rows, x_rel, rate_hz, restarts.starts, restarts.u_m, restarts.v_m_s,
            restarts.force_n, restarts.dial_slope,
        )  # fmt: skip
        if restarts.window is not None:
            slope = restarts.dial_slope
            known = np.isfinite(slope) and slope > 0
            scale = slope * rows[:, layout.P_PROJ] if known else np.ones(rows.shape[0])
            init = refined_starts(
                x_rel, rate_hz, rows, self.stand.friction, restarts.starts, restarts.lengths,
                init, seats, restarts.window, scale, self.substeps, serial,
            )  # fmt: skip
        return runs.simulate_segments(
            x_rel, rate_hz, rows, self.stand.friction, restarts.starts, restarts.lengths, init,
            self.substeps, chained=self.chained, serial=serial, seats=seats,
        )  # fmt: skip

    def stream(self, rate_hz: float, x0_m: float = 0.0) -> ModelStream:
        """The model at static rest with the drive at ``x0_m``, advanced block by block.

        Equal to one ``run`` over the concatenated blocks. A stream cannot look ahead, so
        a negative channel skew (a channel recorded early) is refused.
        """
        return runs.Stream(self.stand, rate_hz, self.effects, x0_m, self.substeps)
