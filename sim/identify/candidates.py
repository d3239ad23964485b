"""What a fit fits: the candidates (the baseline plus effects) and their free parameters.

A candidate's free parameters are the baseline's uncertain ones — fibre stiffness, fibre
damping and the friction table's scale, as multipliers of the nominal stand (log scale
for the first two) — and the effects' fitted parameters within their plausible ranges
(``sim.effects.registry``). Why these three: the paper tuned exactly them; mass,
geometry and g are measured, not uncertain.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from sim.effects import EFFECTS, EffectSpec, ParamInfo
from sim.model import Model, Variant
from sim.params import StandParams

FloatArray = NDArray[np.float64]

#: Baseline multipliers: (name, low, high, log scale).
BASELINE_PARAMS = (
    ("stiffness_scale", 0.5, 2.0, True),
    ("damping_scale", 0.25, 4.0, True),
    ("friction_scale", 0.0, 3.0, False),
)


@dataclass(frozen=True)
class FreeParam:
    """One fitted parameter: its bounds in natural units and the optimiser's scale.

    ``scale``: "lin", "log" (positive, spanning decades) or "asinh" (signed, spanning
    decades: z = asinh(value / width), log-like away from zero, linear through it).
    """

    name: str  # "stiffness_scale", or "<effect>.<param>"
    low: float
    high: float
    scale: str = "lin"
    width: float = 1.0
    #: Where the value typically lies (the start grid is densest there); None: everywhere.
    typical: tuple[float, float] | None = None
    #: Levels (natural units) of a threshold fitted by scanning, held in local fits.
    scan: tuple[float, ...] = ()
    #: A count: scanned at its levels only, not between them.
    integer: bool = False
    #: A form parameter (``ParamInfo.form``) held at this value: not moved by a local fit,
    #: one level in a start grid, the value where a start does not give one. None: fitted.
    held: float | None = None

    def to_internal(self, value: float) -> float:
        """Natural value → optimiser coordinate."""
        if self.scale == "log":
            return float(np.log(value))
        if self.scale == "asinh":
            return float(np.arcsinh(value / self.width))
        return value

    def given(self, values: dict[str, float]) -> float | None:
        """Its value in ``values``, else where it is held; None if neither."""
        return values.get(self.name, self.held)

    def value_in(self, values: dict[str, float]) -> float:
        """Its value in ``values``, else where it is held (KeyError if neither)."""
        value = self.given(values)
        if value is None:
            raise KeyError(self.name)
        return value

    def clipped(self, value: float) -> float:
        """Natural value → optimiser coordinate, clipped into the fitting range first."""
        return self.to_internal(float(np.clip(value, self.low, self.high)))

    def bounds(self) -> tuple[float, float]:
        """Optimiser bounds."""
        return (self.to_internal(self.low), self.to_internal(self.high))

    def to_natural(self, z: float) -> float:
        """Optimiser coordinate → natural value."""
        if self.integer:
            return float(round(z))
        if self.scale == "log":
            return float(np.exp(z))
        if self.scale == "asinh":
            return float(self.width * np.sinh(z))
        return z

    def at_bound(self, value: float, share: float = 2e-3) -> bool:
        """Whether a fitted value ended on a bound (within ``share`` of the range).

        A count's lowest level is a form of the effect, not a limit: only its highest is.
        """
        if self.integer:
            return value >= self.scan[-1] - 0.5
        lo, hi = self.bounds()
        z = self.to_internal(value)
        return bool(z <= lo + share * (hi - lo) or z >= hi - share * (hi - lo))


def _free(effect: str, p: ParamInfo) -> FreeParam:
    """An effect parameter as fitted: within its physical range (``ParamInfo.bounds``)."""
    low, high, typical, name = p.fit_low, p.fit_high, (p.low, p.high), f"{effect}.{p.name}"
    held = p.default if p.form else None
    if p.log and low > 0:
        return FreeParam(name, low, high, "log", 1.0, typical, p.scan, p.integer, held)
    if p.log:  # signed, spanning decades
        width = max(abs(p.low), abs(p.high)) / 4
        return FreeParam(name, low, high, "asinh", width, typical, p.scan, p.integer, held)
    return FreeParam(name, low, high, "lin", 1.0, typical, p.scan, p.integer, held)


@dataclass
class Candidate:
    """The baseline plus some effects (none, one, or a second on top), and their free params."""

    effects: tuple[str, ...] = ()
    params: list[FreeParam] = field(default_factory=list)

    @classmethod
    def build(cls, *effects: str) -> Candidate:
        """Free parameters for a candidate: the baseline's and the effects' fitted ones."""
        params = [FreeParam(n, lo, hi, "log" if lg else "lin") for n, lo, hi, lg in BASELINE_PARAMS]
        for effect in effects:
            params += [_free(effect, p) for p in EFFECTS[effect].params if p.fit]
        return cls(tuple(effects), params)

    @property
    def effect(self) -> str | None:
        """The newest effect (the one this candidate adds), None for the baseline."""
        return self.effects[-1] if self.effects else None

    @property
    def name(self) -> str:
        """The effects' names joined by '+', or 'none' for the baseline."""
        return "+".join(self.effects) or "none"

    def natural(self, z: FloatArray) -> dict[str, float]:
        """Optimiser vector → named natural values."""
        return {p.name: p.to_natural(float(v)) for p, v in zip(self.params, z, strict=True)}

    def internal(self, values: dict[str, float]) -> FloatArray:
        """Named natural values → optimiser vector, each clipped into its fitting range.

        A held form parameter that ``values`` lacks takes its held value.
        """
        return np.array([p.clipped(p.value_in(values)) for p in self.params])

    def freed(self) -> Candidate:
        """The same candidate with its held form parameters fitted too."""
        return Candidate(self.effects, [replace(p, held=None) for p in self.params])

    def model(self, nominal: StandParams, mass_kg: float) -> Model:
        """The candidate's model: the nominal stand at this mass, with its effects."""
        return Model(nominal.with_(mass_kg=mass_kg), [EffectSpec(e) for e in self.effects])

    def variant(self, nominal: StandParams, values: dict[str, float]) -> Variant:
        """The model parameters a set of fitted values describes."""
        changes = {
            "stiffness_n_m": nominal.stiffness_n_m * values["stiffness_scale"],
            "damping_n_s_m": nominal.damping_n_s_m * values["damping_scale"],
            "friction_scale": nominal.friction_scale * values["friction_scale"],
        }
        prefixes = tuple(f"{e}." for e in self.effects)
        changes.update({k: v for k, v in values.items() if k.startswith(prefixes)})
        return changes

    def start_points(self, baseline: dict[str, float] | None) -> list[FloatArray]:
        """Deterministic starts: from the baseline fit (or nominal), effect low/mid/default."""
        base = baseline or {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
        starts = []
        fractions = (0.5,) if not self.effects else (0.15, 0.5, 0.85)
        for frac in fractions:
            z = []
            for p in self.params:
                given = p.given(base)
                if given is not None:
                    z.append(p.clipped(given))
                else:
                    lo, hi = p.bounds()
                    z.append(lo + frac * (hi - lo))
            starts.append(np.array(z))
        return starts


@dataclass(frozen=True)
class FitResult:
    """A fitted candidate and its errors."""

    candidate: Candidate
    values: dict[str, float]
    train_cost: float
    evaluations: int
