"""What an effect is: its parameters (units, ranges and why) and its hooks into the model.

One module per effect under ``sim/effects/`` defines an ``INFO`` of these types; the
registry (``sim.effects.registry.EFFECTS``) lists them. Every parameter has three ranges:

* ``bounds``: what physics and the stand allow (the reason is in ``why`` and in
  docs/effects.md); a diagnosis fits within them, and a fit that ends on one is reported
  "at its bound" (the effect may be larger, or of another form);
* ``low``–``high``: a typical magnitude, clearly visible in the recordings: the check's
  random draws (``EffectInfo.draw``) and the screening probes use it;
* ``minimum``–``maximum``: what the model admits at all (zero magnitudes included);
  ``EffectSpec.resolved`` and ``parse_effect`` refuse values outside it.

The defaults are a typical magnitude: an effect switched on without parameters is
clearly visible where STAND.md §5 says it shows. docs/effects.md gives the equations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from sim.errors import SimulationError
from sim.params import StandParams

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = [
    "EffectError",
    "EffectInfo",
    "InvertGauge",
    "Measured",
    "ParamInfo",
    "RecordGauge",
    "StartState",
    "TrueChannels",
    "param",
]


class EffectError(SimulationError):
    """An effect specification that cannot be used (unknown name or parameter, bad value)."""


@dataclass(frozen=True)
class Measured:
    """What a recording shows at every sample, for setting segment start states.

    ``u_rec_m`` is the recorded (smoothed) displacement channel; ``u_m``, ``v_m_s`` the
    weight's displacement and velocity on the model's scale (the gauge effects inverted);
    ``x_rel_m`` the drive relative to rest; ``force_n`` the recorded (smoothed) force on
    the drive's time base (a skewed force channel shifted back).
    """

    x_rel_m: FloatArray
    rate_hz: float
    u_rec_m: FloatArray
    u_m: FloatArray
    v_m_s: FloatArray
    force_n: FloatArray


#: Fills an effect's columns of ``init`` (segments, ``layout.N_INIT``) for one kernel row:
#: ``start_state(row, measured, starts, init)``.
StartState = Callable[[FloatArray, Measured, IntArray, FloatArray], None]
#: A gauge effect's inverse: ``true_channels(row, rate_hz, u, v, force)`` → (u, v, force)
#: on the model's scale from the recorded ones.
TrueChannels = Callable[
    [FloatArray, float, FloatArray, FloatArray, FloatArray],
    tuple[FloatArray, FloatArray, FloatArray],
]
#: An added gauge effect's transform: ``record(values, t_s, u, force)`` → (u, force) as
#: recorded, with ``values`` its parameters in order and ``t_s`` each sample's time from
#: the recording's start (memoryless: a sample's reading depends on that sample alone).
RecordGauge = Callable[
    [FloatArray, FloatArray, FloatArray, FloatArray], tuple[FloatArray, FloatArray]
]
#: Its inverse: ``invert(values, t_s, u, v, force)`` → (u, v, force) from the recorded ones.
InvertGauge = Callable[
    [FloatArray, FloatArray, FloatArray, FloatArray, FloatArray],
    tuple[FloatArray, FloatArray, FloatArray],
]


@dataclass(frozen=True)
class ParamInfo:
    """One parameter of an effect (SI unit in its name and in ``unit``)."""

    name: str
    unit: str
    default: float
    low: float
    high: float
    minimum: float
    maximum: float
    description: str
    #: Its name in the kernel (``R_<effect symbol>_<symbol>``, ``sim.physics.layout``).
    symbol: str
    fit: bool = True  # worth fitting in a diagnosis (else a fixed physical constant)
    #: Spans decades: drawn and fitted on a log scale; a signed one on a symmetric log
    #: scale (asinh of the value over a quarter of the typical magnitude).
    log: bool = False
    drawn: bool | None = None  # varies between drawn stands (None: as ``fit``)
    bounds: tuple[float, float] = (0.0, 0.0)  # physical range: fitting bounds
    why: str = ""  # why the physical range is what it is
    #: A threshold on recorded events (e.g. how long a slack episode must last): the
    #: output error changes in steps as it crosses the episodes, so a gradient cannot
    #: move it. Fitted by scanning (``scan`` levels, refined between the best's
    #: neighbours), held fixed in the local fits. Empty: fitted by gradient.
    scan: tuple[float, ...] = ()
    #: A count (a scanned threshold taking whole values only): scanned at ``scan`` alone.
    integer: bool = False
    #: Says how the effect acts rather than how large it is (a friction model's presliding
    #: stiffness): held at ``default`` in every candidate's refit, fitted only for the
    #: candidate that fits the training cycles best (``sim.identify.refitting.refine_form``).
    form: bool = False
    #: Its index in the parameter row: given by the registry (``sim.physics.layout``).
    column: int = -1

    @property
    def fit_low(self) -> float:
        """Lower fitting bound (the physical range; the typical range if none is given)."""
        return self.bounds[0] if self.bounds != (0.0, 0.0) else self.low

    @property
    def fit_high(self) -> float:
        """Upper fitting bound."""
        return self.bounds[1] if self.bounds != (0.0, 0.0) else self.high

    @property
    def varies(self) -> bool:
        """Drawn at random for a check's "real" stand."""
        return self.fit if self.drawn is None else self.drawn

    def to_dict(self) -> dict[str, float | str | bool | list[float]]:
        """Plain values (for JSON)."""
        return {
            "name": self.name,
            "unit": self.unit,
            "default": self.default,
            "low": self.low,
            "high": self.high,
            "minimum": self.minimum,
            "maximum": self.maximum,
            "fit": self.fit,
            "form": self.form,
            "log": self.log,
            "bounds": [self.fit_low, self.fit_high],
            "why": self.why,
            "description": self.description,
        }


@dataclass(frozen=True)
class EffectInfo:
    """An effect: what it is, where it shows, and its parameters."""

    name: str
    kind: Literal["physical", "measurement"]
    summary: str
    shows: str
    #: Its name in the kernel (``R_<symbol>_ON`` its flag, ``sim.physics.layout``).
    symbol: str
    params: tuple[ParamInfo, ...]
    #: Its states (string modes, bristles) are invisible to the gauges: a segment of a
    #: multiple-shooting run starts from the previous segment's, not from measurements.
    carried: bool = False
    #: Sets its states at each segment start from the measurements (``StartState``).
    start_state: StartState | None = None
    #: A gauge effect's inverse: the true u, v, force from the recorded ones (``TrueChannels``).
    true_channels: TrueChannels | None = None
    #: Refuses a stand it cannot run on (EffectError), e.g. one without a drive span.
    check_stand: Callable[[StandParams], None] | None = None
    #: An effect added outside the kernel: a compiled force on the weight, N (up the
    #: incline), ``weight_force(u, v, tension, params)`` with params the tuple of its
    #: parameter values in order; the model composes a kernel with it
    #: (``sim.physics.compose``). None for the nine of STAND.md §5, whose terms the
    #: kernel holds.
    weight_force: Any = None
    #: An effect added outside the kernel with terms of its own: the name of the module
    #: (``__name__`` in its one file) whose compiled hooks ``<symbol>_<hook>`` (the hooks
    #: of ``sim.physics.kernel_source``) and helpers ``_<symbol>_…`` the model composes in,
    #: as it does the built-in terms (``sim.physics.added``). None: none.
    terms: str | None = None
    #: A gauge effect added outside (kind "measurement"): what its gauge records
    #: (``RecordGauge``), applied after the built-in gauge chain (``sim.physics.gauges``).
    record: RecordGauge | None = None
    #: Its inverse (``InvertGauge``), for segment restarts from recorded channels; None:
    #: the restarts take the recorded channels as the true ones.
    invert: InvertGauge | None = None
    #: Its continuous states (``terms``): appended after the built-in ones, named
    #: ``Y_<symbol>_<state>`` in its hooks; their values at rest, rates and values at a
    #: measured start come from its ``rest``, ``rates`` and ``start_state`` hooks.
    states: tuple[str, ...] = ()
    #: Its discrete state and derived constants (``terms``): one value each in the
    #: constants array c, named ``S_<symbol>_<slot>`` in its hooks (its ``pack`` sets
    #: constants, its ``after_part`` flips a switch, its ``start`` sets them at a measured
    #: start).
    slots: tuple[str, ...] = ()
    #: How its form can be generalised: the remainder signature variants (kind, channel:
    #: ``sim.identify.signature.VARIANTS``) that a richer form of it would add. A further
    #: effect on top of this one is named only if it beats them (a second effect must not
    #: be this one's form mismatch).
    richer: tuple[tuple[str, str], ...] = ()
    #: Start points for its refit that the recordings or the fit show directly:
    #: ``"module:function"``, ``function(traces, nominal, values) -> [values, ...]``,
    #: imported by the diagnosis where it refits this effect (the function reads
    #: ``sim.identify``'s traces, which this metadata must not import). None: none.
    data_starts: str | None = None
    #: Whether those starts are read again with a refit's own baseline (``read_again``).
    read_again: bool = False
    #: Parameters (s) whose negative value records a channel ahead of the model: a
    #: segment run then starts that much earlier (``fitting.simulate_values``).
    leads: tuple[str, ...] = ()
    #: Its flag's index in the parameter row (its parameters follow): given by the
    #: registry from its place in the registry's order (``sim.physics.layout``).
    flag_column: int = -1
    #: Its first slot's index in c: given by ``register`` (the block from ``layout.S_X``).
    slot_index: int = -1

    @property
    def added(self) -> bool:
        """Added with ``register`` (a compiled force, terms of its own, or a gauge transform)."""
        return self.weight_force is not None or self.terms is not None or self.record is not None

    @property
    def composed(self) -> bool:
        """Added with physics of its own: composed into the compiled model."""
        return self.weight_force is not None or self.terms is not None

    def param(self, name: str) -> ParamInfo:
        """A parameter by name (EffectError if unknown)."""
        for p in self.params:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.params)
        raise EffectError(f"{self.name}: unknown parameter {name!r}; expected one of {known}")

    def defaults(self) -> dict[str, float]:
        """Every parameter at its default."""
        return {p.name: p.default for p in self.params}

    def draw(self, rng: np.random.Generator) -> dict[str, float]:
        """Random varying parameters within their plausible range (others at default)."""
        values = self.defaults()
        for p in self.params:
            if not p.varies:
                continue
            if p.log and p.low > 0 and p.high > 0:
                values[p.name] = float(math.exp(rng.uniform(math.log(p.low), math.log(p.high))))
            else:
                values[p.name] = float(rng.uniform(p.low, p.high))
        return values

    def to_dict(self) -> dict[str, object]:
        """Plain values (for JSON)."""
        return {
            "name": self.name,
            "kind": self.kind,
            "summary": self.summary,
            "shows": self.shows,
            "params": [p.to_dict() for p in self.params],
        }


# fmt: off
def param(name: str, unit: str, default: float, plausible: tuple[float, float],
          admissible: tuple[float, float], symbol: str, description: str, *,
          fit: bool = True, log: bool = False, drawn: bool | None = None,
          bounds: tuple[float, float] = (0.0, 0.0), why: str = "",
          scan: tuple[float, ...] = (), integer: bool = False, form: bool = False) -> ParamInfo:
    """A ParamInfo from the typical (``plausible``) and admissible ranges as pairs."""
    return ParamInfo(name, unit, default, *plausible, *admissible, description, symbol, fit, log,
                     drawn, bounds, why, scan, integer, form)
# fmt: on
