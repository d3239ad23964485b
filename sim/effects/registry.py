"""The nine effects of STAND.md §5: names, parameters, units, ranges, defaults.

Every parameter has three ranges:

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
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from sim.effects import kernel as ek
from sim.errors import SimulationError

__all__ = [
    "EFFECTS",
    "EffectError",
    "EffectInfo",
    "EffectSpec",
    "ParamInfo",
    "parse_effect",
    "parse_effects",
]


class EffectError(SimulationError):
    """An effect specification that cannot be used (unknown name or parameter, bad value)."""


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
    column: int  # index in the kernel's parameter row
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
    flag_column: int
    params: tuple[ParamInfo, ...]

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

    def draw(self, rng: np.random.Generator) -> EffectSpec:
        """Random varying parameters within their plausible range (others at default)."""
        values = self.defaults()
        for p in self.params:
            if not p.varies:
                continue
            if p.log and p.low > 0 and p.high > 0:
                values[p.name] = float(math.exp(rng.uniform(math.log(p.low), math.log(p.high))))
            else:
                values[p.name] = float(rng.uniform(p.low, p.high))
        return EffectSpec(self.name, values)

    def to_dict(self) -> dict[str, object]:
        """Plain values (for JSON)."""
        return {
            "name": self.name,
            "kind": self.kind,
            "summary": self.summary,
            "shows": self.shows,
            "params": [p.to_dict() for p in self.params],
        }


@dataclass(frozen=True)
class EffectSpec:
    """An effect switched on, with the parameters that differ from its defaults."""

    name: str
    params: Mapping[str, float] = field(default_factory=dict)

    def resolved(self) -> dict[str, float]:
        """All parameters (defaults filled in), checked against the admissible ranges."""
        info = effect_info(self.name)
        values = info.defaults()
        for key, raw in self.params.items():
            p = info.param(key)
            value = float(raw)
            if not (math.isfinite(value) and p.minimum <= value <= p.maximum):
                unit = "" if p.unit == "1" else f" {p.unit}"  # dimensionless: no unit
                raise EffectError(
                    f"{self.name}: {key} = {value:g}{unit} is outside its admissible range "
                    f"[{p.minimum:g}, {p.maximum:g}]{unit}"
                )
            values[key] = value
        return values

    def __str__(self) -> str:
        args = ",".join(f"{k}={v:g}" for k, v in self.params.items())
        return f"{self.name}:{args}" if args else self.name


# fmt: off
def _p(name: str, unit: str, default: float, plausible: tuple[float, float],
       admissible: tuple[float, float], column: int, description: str, *,
       fit: bool = True, log: bool = False, drawn: bool | None = None,
       bounds: tuple[float, float] = (0.0, 0.0), why: str = "",
       scan: tuple[float, ...] = ()) -> ParamInfo:
    return ParamInfo(name, unit, default, *plausible, *admissible, description, column, fit, log,
                     drawn, bounds, why, scan)


_INFOS = (
    EffectInfo(
        "fibre_viscoelastic", "physical",
        "standard linear solid: a Maxwell branch (spring k₂ in series with a dashpot "
        "c₂ = k₂·τ) parallel to the fibre's k, c; relaxes while slack",
        "force peaks and ringing damping change with drive rate; slow motion unaffected",
        ek.R_VE_ON,
        (
            _p("branch_stiffness_n_m", "N/m", 2.0e4, (3.0e3, 6.0e4), (0.0, 1.0e6), ek.R_VE_K,
               "k₂, stiffness of the Maxwell branch (whole fibre)", log=True,
               bounds=(5.0e2, 2.0e5),
               why="a polymer-matrix fibre's dynamic stiffness exceeds its static one by a "
                   "few per cent up to several times (k is 34–94 kN/m)"),
            _p("relaxation_time_s", "s", 0.03, (5.0e-3, 0.1), (1.0e-4, 10.0), ek.R_VE_TAU,
               "τ = c₂/k₂, the branch's relaxation time", log=True, bounds=(5.0e-4, 1.0),
               why="faster than one 2 kHz sample it is plain damping; slower than the slowest "
                   "cycle (≈ 1–2.5 s) it is extra stiffness that k absorbs"),
        ),
    ),
    EffectInfo(
        "fibre_transverse_vibration", "physical",
        "first string mode of each free span (f = 1/2ℓ·√(T/μ)), loaded by gravity's "
        "transverse component; its geometric stretch π²a²/4ℓ lengthens the fibre path",
        "force ripple (at 2f, and f with sag) after snatches; displacement nearly unaffected",
        ek.R_TV_ON,
        (
            _p("damping_ratio", "1", 0.02, (0.005, 0.1), (1.0e-4, 1.0), ek.R_TV_ZETA,
               "modal damping ratio of the string modes (at rest tension)", log=True,
               bounds=(1.0e-3, 0.3),
               why="carbon fibre's internal damping is 0.1–1 %; air drag on a slack filament "
                   "bundle adds up to tens of per cent"),
            _p("load_scale", "1", 1.0, (0.5, 2.0), (0.0, 10.0), ek.R_TV_LOAD,
               "multiplier on gravity's transverse load on the spans (0: never excited)",
               bounds=(0.1, 5.0),
               why="drafts, guide misalignment and pulley run-out excite the spans several "
                   "times more than gravity alone; below 0.1 the modes stay in the noise"),
            _p("drive_span_tilt_deg", "deg", 5.0, (0.0, 15.0), (0.0, 90.0), ek.R_TV_TILT,
               "tilt of the (vertical) drive span from the vertical", fit=False),
        ),
    ),
    EffectInfo(
        "fibre_pulley_jump", "physical",
        "once the slack is onset_m deep and has lasted dwell_s the fibre leaves its groove and "
        "re-seats in the other of two seats, changing the effective length by "
        "step_m·(1 − exp(−(slack depth − onset_m)/depth_scale_m))",
        "offset steps in force and position right after slack episodes",
        ek.R_PJ_ON,
        (
            _p("step_m", "m", 2.0e-4, (1.0e-4, 5.0e-4), (-1.0e-2, 1.0e-2), ek.R_PJ_STEP,
               "length change of the second seat (+: effective fibre shorter)", log=True,
               bounds=(-3.0e-3, 3.0e-3),
               why="re-seating across an 80 mm pulley's groove or onto its flange changes the "
                   "fibre path by up to a few millimetres, either way"),
            _p("depth_scale_m", "m", 1.0e-3, (5.0e-4, 5.0e-3), (1.0e-6, 0.1), ek.R_PJ_DEPTH,
               "slack depth over which the fibre completes its jump", log=True,
               bounds=(1.0e-5, 3.0e-2),
               why="from a snap (a hundredth of a millimetre of further slack) to a slow "
                   "slide over a loop as high as the flange (a few cm)"),
            _p("onset_m", "m", 0.0, (0.0, 1.0e-3), (0.0, 0.05), ek.R_PJ_ONSET,
               "slack depth at which the fibre leaves its groove", bounds=(0.0, 5.0e-3),
               why="a fibre held in its groove by friction leaves it only once its loop is "
                   "as deep as the groove or the flange: 0 to a few millimetres"),
            _p("dwell_s", "s", 0.0, (0.0, 0.05), (0.0, 1.0), ek.R_PJ_DWELL,
               "time the fibre lies slack before it leaves its groove", bounds=(0.0, 0.2),
               why="a loose loop slides out of a groove a few millimetres deep under its own "
                   "weight and the groove's friction within tens of milliseconds "
                   "(free fall over 1–10 mm takes 14–45 ms); at once when it is flicked out",
               # 0, then 2 ms to 0.2 s in steps of 20 %: finer than the spread of the
               # slack episodes' lengths (tens of ms) the threshold must fall between.
               scan=(0.0, *(float(v) for v in np.geomspace(2.0e-3, 0.2, 26)))),
        ),
    ),
    EffectInfo(
        "pulley_inertia_friction", "physical",
        "pulley rotation (inertia J) with elasto-plastic bearing friction "
        "(M₀/r + μ_L·hub load); the fibre splits into drive- and weight-side segments",
        "force hysteresis between pull and return, spikes at drive accelerations",
        ek.R_PI_ON,
        (
            _p("inertia_kg_m2", "kg·m²", 1.1e-4, (3.0e-5, 3.0e-4), (1.0e-6, 1.0e-2), ek.R_PI_J,
               "pulley moment of inertia", log=True, bounds=(1.0e-5, 2.0e-3),
               why="an 80 mm aluminium disc 5–10 mm thick has 6e-5–1.1e-4 kg·m²; steel, a "
                   "hub and a shaft raise it to about 1e-3"),
            _p("bearing_torque_n_m", "N·m", 0.01, (0.002, 0.03), (0.0, 0.5), ek.R_PI_TORQUE,
               "load-independent bearing friction torque M₀", bounds=(0.0, 0.1),
               why="a clean ball bearing has about 1e-3 N·m; seals, a plain bush or dirt raise "
                   "it to 0.05–0.1 N·m"),
            _p("load_coeff", "1", 0.005, (0.0, 0.02), (0.0, 0.2), ek.R_PI_LOAD,
               "bearing friction at the rim per newton of hub load (T₁ + T₂)·sin(φ/2)",
               bounds=(0.0, 0.05),
               why="bore friction μ 0.001–0.2 (rolling to plain) times bore/rim radius ≈ 0.25"),
            _p("presliding_m", "m", 1.0e-5, (2.0e-6, 5.0e-5), (1.0e-7, 1.0e-3), ek.R_PI_PRESLIDE,
               "rim displacement before the bearing slides (at rest load)", fit=False, log=True),
        ),
    ),
    EffectInfo(
        "stick_slip_friction", "physical",
        "LuGre friction: bristle state z, ż = v − σ₀|v|z/g(v), F = σ₀z + σ₁ż with "
        "g(v) = table friction·(1 + r·exp(−(v/v_s)²)); needs the stand's friction table",
        "residual at velocity reversals and at low speed, visible in slow tests",
        ek.R_SS_ON,
        (
            _p("static_ratio", "1", 0.4, (0.1, 0.8), (0.0, 5.0), ek.R_SS_RATIO,
               "r: static friction exceeds kinetic by this fraction", bounds=(0.0, 3.0),
               why="static/kinetic friction ratios of steel on lubricated or dry guides lie "
                   "between 1 and about 4"),
            _p("stribeck_speed_m_s", "m/s", 3.0e-3, (1.0e-3, 1.0e-2), (1.0e-5, 1.0), ek.R_SS_VS,
               "v_s: speed over which friction falls to kinetic", log=True,
               bounds=(1.0e-4, 0.1),
               why="lubricated line contacts show Stribeck speeds from 0.1 mm/s to 0.1 m/s"),
            _p("bristle_stiffness_n_m", "N/m", 1.0e5, (3.0e4, 3.0e5), (1.0e3, 1.0e7),
               ek.R_SS_SIGMA, "σ₀, presliding stiffness (σ₁ = 2√(σ₀m))", fit=False, log=True),
        ),
    ),
    EffectInfo(
        "side_load_friction", "physical",
        "the lateral pull T·sin β presses the weight on the guide wall: extra friction "
        "μ_s·T·sin β (T the weight-side tension), zero while slack",
        "friction that grows with tension and vanishes when slack",
        ek.R_SL_ON,
        (
            _p("friction_coeff", "1", 0.1, (0.03, 0.3), (0.0, 2.0), ek.R_SL_MU,
               "μ_s, friction coefficient of the guide wall", bounds=(0.0, 0.8),
               why="steel or aluminium on a dry guide wall: up to 0.6–0.8"),
        ),
    ),
    EffectInfo(
        "dial_gauge_calibration", "measurement",
        "u_rec = (1 + gain_error)·u + offset_m",
        "residual ∝ u in every test; force unaffected",
        ek.R_DG_ON,
        (
            _p("gain_error", "1", 0.02, (-0.04, 0.04), (-0.5, 0.5), ek.R_DG_GAIN,
               "relative gain error of the dial gauge", bounds=(-0.2, 0.2),
               why="a gauge mounted at an angle to the incline reads u/cos θ (15 % at 30°); "
                   "a lever gauge's arm angle and a mis-set scale add a few per cent"),
            # Not fitted: recordings count u from their rest reading, which removes it;
            # under multiple shooting a fitted offset would pose as a fibre length change.
            # Still drawn, so the check shows it is harmless.
            _p("offset_m", "m", 0.0, (-2.0e-4, 2.0e-4), (-0.01, 0.01), ek.R_DG_OFFSET,
               "reading at u = 0", fit=False, drawn=True),
        ),
    ),
    EffectInfo(
        "channel_time_skew", "measurement",
        "a channel is sampled Δt late (Δt < 0: early) against the drive channel",
        "residual ∝ the channel's derivative; cross-correlation peak off zero",
        ek.R_CS_ON,
        (
            _p("force_skew_s", "s", 1.0e-3, (-3.0e-3, 3.0e-3), (-0.05, 0.05), ek.R_CS_FORCE,
               "delay of the force channel", log=True, bounds=(-0.025, 0.025),
               why="separate buffers, serial latency and filter delays: up to 50 samples "
                   "(25 ms) either way at 2 kHz"),
            _p("displacement_skew_s", "s", 0.0, (-3.0e-3, 3.0e-3), (-0.05, 0.05), ek.R_CS_DISP,
               "delay of the displacement channel", log=True, bounds=(-0.025, 0.025),
               why="as the force channel's"),
        ),
    ),
    EffectInfo(
        "force_gauge_dynamics", "measurement",
        "the force gauge and amplifier: second-order low-pass ω²/(s² + 2ζωs + ω²)",
        "force peaks attenuated and delayed; displacement unaffected",
        ek.R_FG_ON,
        (
            _p("cutoff_hz", "Hz", 80.0, (30.0, 300.0), (1.0, 1.0e5), ek.R_FG_FC,
               "natural frequency ω/2π of the low-pass", log=True, bounds=(5.0, 2000.0),
               why="strain-gauge amplifiers filter at 10 Hz to a few kHz; above 1 kHz a "
                   "2 kHz recording cannot see it"),
            _p("damping_ratio", "1", 0.7, (0.5, 1.2), (0.05, 10.0), ek.R_FG_ZETA,
               "ζ of the low-pass (≥ 1: no overshoot, first-order-like)", bounds=(0.2, 3.0),
               why="a lightly damped load cell 0.2; Butterworth/Bessel filters 0.7–0.9; "
                   "cascaded RC stages overdamped"),
        ),
    ),
)
# fmt: on

#: The effects by name, in STAND.md §5 order.
EFFECTS: dict[str, EffectInfo] = {info.name: info for info in _INFOS}


def effect_info(name: str) -> EffectInfo:
    """An effect by name (EffectError naming the known ones if unknown)."""
    try:
        return EFFECTS[name]
    except KeyError:
        raise EffectError(f"unknown effect {name!r}; known: {', '.join(EFFECTS)}") from None


def parse_effect(text: str) -> EffectSpec:
    """``NAME[:param=value,...]`` → a checked EffectSpec (EffectError, one line, if bad)."""
    name, _, rest = text.strip().partition(":")
    info = effect_info(name.strip())
    params: dict[str, float] = {}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, raw = item.partition("=")
        key = key.strip()
        if not eq:
            raise EffectError(f"{info.name}: expected param=value, got {item!r}")
        unit = info.param(key).unit
        if key in params:
            raise EffectError(f"{info.name}: {key} given twice")
        try:
            params[key] = float(raw)
        except ValueError:
            raise EffectError(
                f"{info.name}: {key} must be a number ({unit}), got {raw!r}"
            ) from None
    spec = EffectSpec(info.name, params)
    spec.resolved()
    return spec


def parse_effects(texts: Iterable[str]) -> list[EffectSpec]:
    """Several ``--effect`` values; ``none`` means no effect; each effect at most once."""
    specs = [parse_effect(t) for t in texts if t.strip() != "none"]
    check_unique(specs)
    return specs


def check_unique(specs: Iterable[EffectSpec]) -> None:
    """EffectError if an effect is named twice."""
    seen: set[str] = set()
    for spec in specs:
        if spec.name in seen:
            raise EffectError(f"effect {spec.name} given twice")
        seen.add(spec.name)
