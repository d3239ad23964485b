"""The nine effects of STAND.md §5 in a second formulation, with their own ranges.

This is the "other lab's stand": each effect is written from STAND.md's one-line
description alone, in a mathematical form deliberately unlike the candidate models of
``sim.effects`` (which this package never imports), with parameter ranges argued from the
hardware rather than from the candidates' bounds. A diagnosis that names these effects is
robust to the form of the effect, not only to its magnitude.

Each effect is an ``OtherEffect``: its kind, a one-line form, the parameter values that
switch it off (``zero``) and ``draw(rng)``, whose docstring says why its ranges are what
they are. Parameters are SI; names carry the unit. docs/effects.md ("The second
formulations") gives the equations.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = ["OTHER_EFFECTS", "OTHER_PAIRS", "OTHER_TRIPLES", "OtherEffect"]

Params = dict[str, float]


def _log_uniform(rng: np.random.Generator, low: float, high: float) -> float:
    return float(math.exp(rng.uniform(math.log(low), math.log(high))))


def _sign(rng: np.random.Generator) -> float:
    return 1.0 if rng.uniform() < 0.5 else -1.0


def _fibre_viscoelastic(rng: np.random.Generator) -> Params:
    """Two Maxwell branches in parallel with the fibre (a two-term Prony series).

    A carbon tow is thousands of filaments held by a polymer sizing; its relaxation
    spectrum is broad, so one time constant is a simplification. A fast branch (the
    sizing's glassy response, τ 2–20 ms) and a slow one (filament sliding and the tow
    settling, τ 60–600 ms). Branch stiffnesses are given relative to the stand's
    static k: the dynamic modulus of sized carbon tows exceeds the static one by
    10–80 % at tens of Hz (fast branch 0.1–0.8·k), the slow branch 0.05–0.4·k. Ratios,
    not newtons per metre, because the fibre's k is itself uncertain by ±25 %.
    """
    return {
        "fast_ratio": _log_uniform(rng, 0.1, 0.8),
        "fast_tau_s": _log_uniform(rng, 2e-3, 2e-2),
        "slow_ratio": _log_uniform(rng, 0.05, 0.4),
        "slow_tau_s": _log_uniform(rng, 0.06, 0.6),
    }


def _fibre_transverse_vibration(rng: np.random.Generator) -> Params:
    """Three string modes per span, frequency-proportional damping and air drag.

    The modes are excited by gravity and by the weight's motion across the span.

    Loss factor η 0.01–0.1 (damping force η·ω(T)·ȧ, ω following the tension): a dry tow
    rubs its filaments against each other, a loss factor of a few per cent is typical of
    fibre bundles. Air drag with an effective width C_d·D of 1–6 mm (a flat tow of 1–3 mm
    width, C_d of a strip 1.2–2). Drive span tilt 0–10°: the drive span is vertical only
    as far as the drive was aligned by eye. ``load_scale`` (1 in every draw; 0 switches
    the excitation off) multiplies gravity's and the end's transverse loads.
    """
    return {
        "loss_factor": _log_uniform(rng, 0.01, 0.1),
        "drag_width_m": _log_uniform(rng, 1e-3, 6e-3),
        "drive_span_tilt_deg": float(rng.uniform(0.0, 10.0)),
        "load_scale": 1.0,
    }


def _fibre_pulley_jump(rng: np.random.Generator) -> Params:
    """A ratchet of seats, creeping, the length change split between the spans.

    Each slack episode deeper than a threshold moves the fibre one seat along the groove
    (up to the flange), the seat creeping there with a time constant.

    Step 0.1–2 mm either sign: the fibre riding up the groove flank by Δr changes the
    wrapped path by about Δr·φ (φ = 2.16 rad), and a groove of an 80 mm pulley is 1–2 mm
    deep; sign + means the path got longer (the effective fibre shorter). Threshold
    0.3–3 mm of slack: the fibre has to be loose enough to lift off the groove. Time
    constant 2–30 ms: the fibre is light, but friction on the flank slows the seat.
    2–4 seats. Split: the share of the change appearing on the drive span, 0.2–0.8.
    """
    return {
        "step_m": _sign(rng) * _log_uniform(rng, 1e-4, 2e-3),
        "threshold_m": _log_uniform(rng, 3e-4, 3e-3),
        "tau_s": _log_uniform(rng, 2e-3, 3e-2),
        "seats": float(rng.integers(2, 5)),
        "drive_share": float(rng.uniform(0.2, 0.8)),
    }


def _pulley_inertia_friction(rng: np.random.Generator) -> Params:
    """Pulley inertia; bearing friction Coulomb + breakaway + viscous, sticking (Karnopp).

    Static above kinetic, no load dependence.

    Inertia 3·10⁻⁵–5·10⁻⁴ kg·m²: an 80 mm pulley, 8–15 mm thick, in POM, aluminium or
    steel, with its hub. Kinetic torque 2·10⁻³–4·10⁻² N·m: a small sealed ball bearing's
    seal drag (the load term of a ball bearing, ~0.0015·load·bore/2, is below 10⁻³ N·m
    here), up to a plain bush. Breakaway 10–150 % above kinetic (a sealed bearing after a
    pause). Viscous 10⁻⁵–3·10⁻⁴ N·m·s (grease churning).
    """
    return {
        "inertia_kg_m2": _log_uniform(rng, 3e-5, 5e-4),
        "kinetic_torque_n_m": _log_uniform(rng, 2e-3, 4e-2),
        "breakaway_ratio": float(rng.uniform(0.1, 1.5)),
        "viscous_n_m_s": _log_uniform(rng, 1e-5, 3e-4),
    }


def _stick_slip_friction(rng: np.random.Generator) -> Params:
    """Stribeck curve plus a Karnopp stick band instead of a bristle model.

    Friction at speed v: the stand's table plus r·F_c·exp(−(v/v_s)^e); below a velocity
    band the weight sticks while the applied force stays under the static level
    (1 + r)·F_c. Static excess r 0.2–1.5 (lubricated steel on steel: static 1.2–2.5×
    kinetic), Stribeck speed 2 mm/s–8 cm/s (mixed lubrication of a greased prismatic
    guide, wide because the grease and the load vary), exponent e 0.5–2 (exponential to
    Gaussian decay, both seen in the tribology literature).
    """
    return {
        "static_excess": float(rng.uniform(0.2, 1.5)),
        "stribeck_speed_m_s": _log_uniform(rng, 2e-3, 8e-2),
        "stribeck_exponent": float(rng.uniform(0.5, 2.0)),
    }


def _side_load_friction(rng: np.random.Generator) -> Params:
    """Wall friction from the lateral pull, growing nonlinearly with tension.

    μ_w·sin β·T·(T/T_ref)^(p−1), T_ref = 50 N (the weight-side tension, zero when slack).

    μ_w 0.05–0.25 (greased to dry steel on the guide's wall). Exponent p either 1.3–1.8
    (the fibre is attached above the guide, so the lateral pull also tilts the weight and
    edge-loads the wall: the contact force grows faster than T) or 0.5–0.8 (a compliant
    wall lining seats the weight and shares the load with the guide's floor: it grows
    slower). Never exactly 1: that is the candidate's form. T_ref is a fixed scale of the
    stand's working tensions (17–45 N at rest, a few hundred newtons at snatches).
    """
    p = float(rng.uniform(1.3, 1.8)) if rng.uniform() < 0.5 else float(rng.uniform(0.5, 0.8))
    return {"wall_mu": float(rng.uniform(0.05, 0.25)), "exponent": p}


def _dial_gauge_calibration(rng: np.random.Generator) -> Params:
    """Gain, offset, a quadratic nonlinearity and backlash of a dial gauge.

    Gain 1 ± 1–12 %: a gauge mounted at an angle θ to the motion reads u·cos θ (−1 % at
    8°, −10 % at 26°) and a lever indicator reads u/cos θ; the asymmetric stand makes a
    tilted mounting likely. Offset ±0.5 mm (zeroed by hand). Curvature ±0.05 /m: a rack
    and pinion with a pitch error of a few hundredths of a millimetre over 70 mm.
    Backlash 0–30 µm: a couple of the dial's 0.01 mm divisions of play in the gears.
    """
    return {
        "gain": 1.0 + _sign(rng) * float(rng.uniform(0.01, 0.12)),
        "offset_m": float(rng.uniform(-5e-4, 5e-4)),
        "curvature_1_m": float(rng.uniform(-0.05, 0.05)),
        "backlash_m": float(rng.uniform(0.0, 3e-5)),
    }


def _channel_time_skew(rng: np.random.Generator) -> Params:
    """A fractional-sample delay (band-limited cubic interpolation) on either channel.

    Half the draws are a sub-millisecond-to-few-millisecond skew (0.2–4 ms: multiplexed
    ADC and sample-and-hold timing), half a buffering offset of 2–50 samples (1–25 ms: a
    USB or serial buffer flushed late or early relative to the drive's encoder), each of
    either sign. The skewed channel is the force, the displacement, or both (with
    independent delays), equally likely.
    """
    delays = []
    for _ in range(2):
        if rng.uniform() < 0.5:
            d = float(rng.uniform(2e-4, 4e-3))
        else:
            d = float(rng.integers(2, 51)) / 2000.0 + float(rng.uniform(-2.5e-4, 2.5e-4))
        delays.append(_sign(rng) * d)
    which = int(rng.integers(0, 3))  # 0: force, 1: displacement, 2: both
    return {
        "force_delay_s": delays[0] if which in (0, 2) else 0.0,
        "displacement_delay_s": delays[1] if which in (1, 2) else 0.0,
    }


def _force_gauge_dynamics(rng: np.random.Generator) -> Params:
    """A first-order amplifier low-pass after the load cell's lightly damped resonance.

    Amplifier corner 20–200 Hz (strain-gauge bridge amplifiers ship with 10 Hz–1 kHz
    filters; the stand's was set low against hum). Load cell with its adapter and clamp:
    a resonance at 150–600 Hz with ζ 0.03–0.2 (a metal spring element, damped little).
    """
    return {
        "amplifier_cutoff_hz": _log_uniform(rng, 20.0, 200.0),
        "cell_frequency_hz": _log_uniform(rng, 150.0, 600.0),
        "cell_damping": _log_uniform(rng, 0.03, 0.2),
    }


@dataclass(frozen=True)
class OtherEffect:
    """One effect of the other stand: kind, form, off values, and a random draw."""

    name: str
    kind: Literal["physical", "measurement"]
    form: str
    zero: Mapping[str, float]
    draw_params: Callable[[np.random.Generator], Params]

    def draw(self, rng: np.random.Generator) -> Params:
        """Random parameters within the effect's physical ranges (see ``why``)."""
        return self.draw_params(rng)

    @property
    def why(self) -> str:
        """The reasons for the form and the ranges (the draw function's docstring)."""
        return self.draw_params.__doc__ or ""

    def params(self, given: Mapping[str, float]) -> Params:
        """All parameters: the given ones over the off values (unknown names refused)."""
        unknown = set(given) - set(self.zero)
        if unknown:
            raise ValueError(f"{self.name}: unknown parameter(s) {', '.join(sorted(unknown))}")
        return {**self.zero, **{k: float(v) for k, v in given.items()}}


# fmt: off
_LIST = (
    OtherEffect("fibre_viscoelastic", "physical", "two Maxwell branches (Prony series)",
                {"fast_ratio": 0.0, "fast_tau_s": 0.01, "slow_ratio": 0.0, "slow_tau_s": 0.2},
                _fibre_viscoelastic),
    OtherEffect("fibre_transverse_vibration", "physical",
                "3 string modes per span, η·ω(T) damping + air drag, gravity + end excitation",
                {"loss_factor": 0.03, "drag_width_m": 0.0, "drive_span_tilt_deg": 0.0,
                 "load_scale": 0.0}, _fibre_transverse_vibration),
    OtherEffect("fibre_pulley_jump", "physical", "ratchet of seats, creeping, split spans",
                {"step_m": 0.0, "threshold_m": 1e-3, "tau_s": 0.01, "seats": 2.0,
                 "drive_share": 0.5}, _fibre_pulley_jump),
    OtherEffect("pulley_inertia_friction", "physical",
                "inertia, Coulomb + breakaway + viscous bearing (Karnopp)",
                {"inertia_kg_m2": 0.0, "kinetic_torque_n_m": 0.0, "breakaway_ratio": 0.0,
                 "viscous_n_m_s": 0.0}, _pulley_inertia_friction),
    OtherEffect("stick_slip_friction", "physical", "Stribeck + Karnopp stick band",
                {"static_excess": 0.0, "stribeck_speed_m_s": 0.01, "stribeck_exponent": 1.0},
                _stick_slip_friction),
    OtherEffect("side_load_friction", "physical", "μ_w·sin β·T·(T/T_ref)^(p−1)",
                {"wall_mu": 0.0, "exponent": 1.5}, _side_load_friction),
    OtherEffect("dial_gauge_calibration", "measurement",
                "gain, offset, quadratic curvature, backlash",
                {"gain": 1.0, "offset_m": 0.0, "curvature_1_m": 0.0, "backlash_m": 0.0},
                _dial_gauge_calibration),
    OtherEffect("channel_time_skew", "measurement", "fractional delay (cubic) on either channel",
                {"force_delay_s": 0.0, "displacement_delay_s": 0.0}, _channel_time_skew),
    OtherEffect("force_gauge_dynamics", "measurement",
                "first-order amplifier × lightly damped load-cell resonance",
                {"amplifier_cutoff_hz": 0.0, "cell_frequency_hz": 0.0, "cell_damping": 0.1},
                _force_gauge_dynamics),
)
# fmt: on

#: The second formulations by name, in STAND.md §5 order.
OTHER_EFFECTS: dict[str, OtherEffect] = {e.name: e for e in _LIST}

#: Two effects at once: one physical with one measurement effect, and physical pairs that
#: compose (each term acts on its own part of the stand).
OTHER_PAIRS: tuple[tuple[str, str], ...] = (
    ("fibre_viscoelastic", "dial_gauge_calibration"),
    ("stick_slip_friction", "channel_time_skew"),
    ("pulley_inertia_friction", "force_gauge_dynamics"),
    ("side_load_friction", "dial_gauge_calibration"),
    ("fibre_pulley_jump", "channel_time_skew"),
    ("fibre_transverse_vibration", "stick_slip_friction"),
    ("pulley_inertia_friction", "fibre_pulley_jump"),
    ("fibre_viscoelastic", "side_load_friction"),
)

#: Three effects at once: a friction, a seat and a pulley (the stand the paper suspected);
#: a fibre law with two gauges; a side load, the strings and a gauge low-pass.
OTHER_TRIPLES: tuple[tuple[str, str, str], ...] = (
    ("stick_slip_friction", "fibre_pulley_jump", "pulley_inertia_friction"),
    ("fibre_viscoelastic", "dial_gauge_calibration", "channel_time_skew"),
    ("side_load_friction", "fibre_transverse_vibration", "force_gauge_dynamics"),
)
