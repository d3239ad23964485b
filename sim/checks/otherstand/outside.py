"""Effects outside the catalogue: what a real stand may have that no candidate models.

The diagnosis's nine candidates (STAND.md §5) are not all a stand can do. These five are
physically plausible for this stand and of different kinds, so a check can ask whether
the diagnosis says "unexplained" rather than blaming an innocent candidate, and whether
its signature names the right kind of term (``signature_kind``):

* ``fibre_strain_stiffening`` (strain): a tow's filaments straighten under load, its
  tangent stiffness grows (or, for a worn tow, falls) with tension;
* ``guide_waviness`` (position): a bowed or wavy guide, a force along it that varies
  with the weight's position;
* ``guide_drag`` (velocity): an oiled guide or a dashpot, viscous plus quadratic drag
  on the weight;
* ``anchor_resonance`` (resonance): the drive's end of the fibre on a compliant
  carriage, a mode of its own excited by the tension;
* ``force_gauge_drift`` (drift): the load cell warming up, its zero creeping within
  each recording.

Like ``effects``, each is an ``OtherEffect`` whose draw function says why its ranges
are what they are; the kernel's ``P_HARD`` … ``P_FR_M`` carry the physical ones and
``force_drift`` the gauge's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from sim.checks.otherstand import _kernel as kern
from sim.checks.otherstand.effects import OTHER_EFFECTS, OtherEffect, Params, _log_uniform, _sign
from sim.params import StandParams

FloatArray = NDArray[np.float64]

__all__ = ["ALL_EFFECTS", "OUTSIDE_EFFECTS", "check_effects", "fill_outside", "force_drift"]


def _fibre_strain_stiffening(rng: np.random.Generator) -> Params:
    """Tangent stiffness k·(1 + 2h·T/50 N): h 0.05–0.3 stiffening, or 0.03–0.1 softening.

    A carbon tow's filaments are not equally long: the slack ones take load only as the
    tow stretches, so its stiffness rises with tension (the "toe" of its curve), by tens
    of per cent over the stand's 0–100 N. A tow worn on the pulley has broken filaments
    and can soften instead (less: a tow that soft would soon break); three in ten draws.
    """
    if rng.uniform() < 0.3:
        return {"hardening": -_log_uniform(rng, 0.03, 0.1)}
    return {"hardening": _log_uniform(rng, 0.05, 0.3)}


def _guide_waviness(rng: np.random.Generator) -> Params:
    """A force A·sin(2π·u/λ + φ) along the guide: A 0.5–3 N, λ 60–250 mm.

    A guide rail bowed by its mounting, or an incline whose plane is not flat: a slope
    change of 1–3 % over a wavelength moves gravity's component along the guide by
    0.3–2.4 N for the 3–8 kg weights, plus rolling resistance that varies along it.
    """
    return {
        "amplitude_n": _log_uniform(rng, 0.5, 3.0),
        "wavelength_m": _log_uniform(rng, 0.06, 0.25),
        "phase_rad": float(rng.uniform(0.0, 2 * math.pi)),
    }


def _guide_drag(rng: np.random.Generator) -> Params:
    """Viscous drag b·v (b 5–30 N·s/m) and quadratic drag d·v·|v| (d 5–40 N·s²/m²).

    An oiled guide or a felt wiper: a film of 0.1 mm of oil under a 40 cm² shoe gives a
    few N·s/m to tens; the quadratic part, of a shoe ploughing its lubricant, is of the
    same order at the weight's 0.1–0.5 m/s.
    """
    return {
        "viscous_n_s_m": _log_uniform(rng, 5.0, 30.0),
        "quadratic_n_s2_m2": _log_uniform(rng, 5.0, 40.0),
    }


def _anchor_resonance(rng: np.random.Generator) -> Params:
    """The drive's end of the fibre on a carriage: a mode at 15–60 Hz, ζ 0.02–0.1.

    The force gauge and its clamp sit on the drive's carriage, half a kilogram to three
    on a slide pulled by a toothed belt: a belt's stiffness of 10⁴–10⁵ N/m puts its
    mode along the fibre at 15–60 Hz (as stiff as the fibre itself, or stiffer), lightly
    damped, excited by every change of the tension. (A stiff screw drive's carriage,
    above 100 Hz, only adds compliance that a fitted fibre stiffness takes up.)
    """
    return {
        "frequency_hz": _log_uniform(rng, 15.0, 60.0),
        "damping_ratio": _log_uniform(rng, 0.02, 0.1),
        "mass_kg": _log_uniform(rng, 0.5, 3.0),
    }


def _force_gauge_drift(rng: np.random.Generator) -> Params:
    """The zero of the force reading creeping by D·(1 − e^(−t/τ)): D 0.4–2 N, τ 2–20 s.

    A strain-gauge load cell and its amplifier warm up after switching on or after a
    change of load: zero drifts of 0.02–0.1 % of a 2 kN range are typical, settling
    over seconds to minutes. Either sign; each recording starts its own creep (the gauge
    is zeroed before it).
    """
    return {
        "drift_n": _sign(rng) * _log_uniform(rng, 0.4, 2.0),
        "time_constant_s": _log_uniform(rng, 2.0, 20.0),
    }


# fmt: off
_LIST = (
    OtherEffect("fibre_strain_stiffening", "physical", "k·d·(1 + h·k·d/50 N)",
                {"hardening": 0.0}, _fibre_strain_stiffening),
    OtherEffect("guide_waviness", "physical", "A·sin(2π·u/λ + φ) along the guide",
                {"amplitude_n": 0.0, "wavelength_m": 0.1, "phase_rad": 0.0}, _guide_waviness),
    OtherEffect("guide_drag", "physical", "b·v + d·v·|v| on the weight",
                {"viscous_n_s_m": 0.0, "quadratic_n_s2_m2": 0.0}, _guide_drag),
    OtherEffect("anchor_resonance", "physical", "a carriage mode between drive and fibre",
                {"frequency_hz": 0.0, "damping_ratio": 0.05, "mass_kg": 1.0},
                _anchor_resonance),
    OtherEffect("force_gauge_drift", "measurement", "zero creep D·(1 − e^(−t/τ))",
                {"drift_n": 0.0, "time_constant_s": 10.0}, _force_gauge_drift),
)
# fmt: on

#: The out-of-catalogue effects by name.
OUTSIDE_EFFECTS: dict[str, OtherEffect] = {e.name: e for e in _LIST}
#: What each one's signature should be (``sim.identify.signature.KINDS``).
SIGNATURE_KIND = {
    "fibre_strain_stiffening": "strain",
    "guide_waviness": "position",
    "guide_drag": "velocity",
    "anchor_resonance": "resonance",
    "force_gauge_drift": "drift",
}
#: Every effect the other stand knows: the second formulations and these.
ALL_EFFECTS: dict[str, OtherEffect] = {**OTHER_EFFECTS, **OUTSIDE_EFFECTS}


def check_effects(effects: Mapping[str, Mapping[str, float]]) -> dict[str, Params]:
    """Every named effect's full parameter set (ValueError naming an unknown effect)."""
    out: dict[str, Params] = {}
    for name, given in effects.items():
        if name not in ALL_EFFECTS:
            raise ValueError(f"unknown effect {name!r}; known: {', '.join(ALL_EFFECTS)}")
        out[name] = ALL_EFFECTS[name].params(given)
    return out


def fill_outside(p: FloatArray, stand: StandParams, effects: Mapping[str, Params]) -> None:
    """Set the kernel row's out-of-catalogue terms for the physical effects named."""
    if "fibre_strain_stiffening" in effects:
        p[kern.P_HARD] = effects["fibre_strain_stiffening"]["hardening"]
    if "guide_waviness" in effects:
        v = effects["guide_waviness"]
        p[kern.P_WAVE_A] = v["amplitude_n"]
        p[kern.P_WAVE_K] = 2 * math.pi / v["wavelength_m"]
        p[kern.P_WAVE_PH] = v["phase_rad"]
    if "guide_drag" in effects:
        v = effects["guide_drag"]
        p[kern.P_VISC], p[kern.P_QDRAG] = v["viscous_n_s_m"], v["quadratic_n_s2_m2"]
    if "anchor_resonance" in effects and effects["anchor_resonance"]["frequency_hz"] > 0:
        v = effects["anchor_resonance"]
        p[kern.P_FR_ON] = 1.0
        p[kern.P_FR_W] = 2 * math.pi * v["frequency_hz"]
        p[kern.P_FR_Z], p[kern.P_FR_M] = v["damping_ratio"], v["mass_kg"]


def force_drift(force_n: FloatArray, rate_hz: float, params: Mapping[str, float]) -> FloatArray:
    """The force reading with its zero creeping from the recording's start."""
    t = np.arange(force_n.size) / rate_hz
    creep = params["drift_n"] * (1.0 - np.exp(-t / params["time_constant_s"]))
    return np.asarray(force_n + creep, dtype=np.float64)
