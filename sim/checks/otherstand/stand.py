"""The other stand: STAND.md §2 and the second formulations of §5, run from static rest.

``simulate(stand, effects, x_m, rate_hz)`` runs the physics (``_kernel``) at a fine
rate and passes it through the gauges (``gauges.record``). ``stand`` is a
``sim.params.StandParams`` (geometry, the true k, c, friction); ``effects`` maps effect
names of ``OTHER_EFFECTS`` (or ``outside.OUTSIDE_EFFECTS``) to their parameters
(missing ones take the off values).
Several effects compose: each acts on its own part of the stand.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.checks.otherstand import _kernel as kern
from sim.checks.otherstand.gauges import record
from sim.checks.otherstand.outside import ALL_EFFECTS, check_effects, fill_outside
from sim.params import StandParams

FloatArray = NDArray[np.float64]

__all__ = ["OVERSAMPLE", "SUBSTEPS", "OtherRun", "simulate"]

#: Physics outputs per sample interval (the gauges filter and delay this fine signal).
OVERSAMPLE = 4
#: RK4 steps per fine output: 2 kHz × 4 × 5 = 40 kHz, a 25 µs step.
SUBSTEPS = 5
#: Karnopp stick band, m/s, and the time constant that holds a stuck body, s.
STICK_BAND_M_S = 1e-4
STICK_TAU_S = 5e-4


@dataclass(frozen=True)
class OtherRun:
    """One run (SI): recorded-like noise-free channels and the true ones, at the sample rate."""

    t_s: FloatArray
    x_m: FloatArray
    u_m: FloatArray  # as the dial gauge records it (gauge effects, skew; no noise)
    force_n: FloatArray  # as the force gauge records it
    true_u_m: FloatArray
    true_force_n: FloatArray  # drive-side tension
    weight_force_n: FloatArray  # weight-side tension
    seat_m: FloatArray  # the pulley seat's length change
    preload_tension_n: float


def _friction_pieces(stand: StandParams) -> tuple[FloatArray, FloatArray]:
    if stand.friction is None:
        return np.array([0.0, 1.0]), np.zeros((4, 1))
    pchip = stand.friction.pchip()
    return np.asarray(pchip.x, dtype=np.float64), np.ascontiguousarray(pchip.c, dtype=np.float64)


def parameter_row(
    stand: StandParams, effects: Mapping[str, Mapping[str, float]]
) -> tuple[FloatArray, FloatArray]:
    """The kernel's parameter row and the strings' rest sag (6,) for a stand and effects."""
    e = check_effects(effects)
    p = np.zeros(kern.N_PARAM)
    n = stand.projection
    alpha = math.radians(stand.incline_deg)
    sin_b = stand.lateral_offset_m / stand.free_length_m
    half_wrap = stand.pulley_radius_m * math.radians(stand.wrap_angle_deg) / 2
    friction_n = stand.normal_force_n * stand.friction_scale if stand.friction else 0.0
    p[kern.P_M], p[kern.P_K] = stand.mass_kg, stand.stiffness_n_m
    p[kern.P_C], p[kern.P_N] = stand.damping_n_s_m, n
    p[kern.P_MGS], p[kern.P_T0] = stand.gravity_along_n, stand.preload_tension_n
    p[kern.P_NORMAL], p[kern.P_G] = friction_n, stand.gravity_m_s2
    p[kern.P_VREG] = stand.friction.v_reg_m_s if stand.friction else 1e-3
    p[kern.P_L1], p[kern.P_L2] = stand.drive_span_m, stand.free_length_m
    p[kern.P_SEG1], p[kern.P_SEG2] = stand.drive_span_m + half_wrap, stand.free_length_m + half_wrap
    p[kern.P_LTOT] = p[kern.P_SEG1] + p[kern.P_SEG2]
    p[kern.P_MU] = stand.linear_density_kg_m
    p[kern.P_SINB] = sin_b
    p[kern.P_TSTICK], p[kern.P_VBAND] = STICK_TAU_S, STICK_BAND_M_S
    p[kern.P_TAUS] = 1.0
    arest = np.zeros(2 * kern.N_MODES)
    if "fibre_viscoelastic" in e:
        v = e["fibre_viscoelastic"]
        p[kern.P_VE_ON] = 1.0
        p[kern.P_KA], p[kern.P_TAUA] = v["fast_ratio"] * stand.stiffness_n_m, v["fast_tau_s"]
        p[kern.P_KB], p[kern.P_TAUB] = v["slow_ratio"] * stand.stiffness_n_m, v["slow_tau_s"]
    if "fibre_transverse_vibration" in e:
        v = e["fibre_transverse_vibration"]
        g, scale = stand.gravity_m_s2, v["load_scale"]
        vertical = n * math.sin(alpha)  # vertical component of the weight span's direction
        p[kern.P_TV_ON] = 1.0
        p[kern.P_ETA] = v["loss_factor"]
        # Drag of a strip, per unit modal mass (|sin|³ averaged over the span: 4/3π).
        p[kern.P_DRAG] = 4 * 1.2 * v["drag_width_m"] / (3 * math.pi * stand.linear_density_kg_m)
        p[kern.P_GP1] = scale * g * math.sin(math.radians(v["drive_span_tilt_deg"]))
        p[kern.P_GP2] = scale * g * math.sqrt(1 - vertical**2)
        # The weight's motion along the guide, seen across the span in the sag plane.
        p[kern.P_EXC] = -scale * math.sin(alpha) * sin_b**2 / math.sqrt(1 - vertical**2)
        for span, (ell, gp) in enumerate(
            ((p[kern.P_L1], p[kern.P_GP1]), (p[kern.P_L2], p[kern.P_GP2]))
        ):
            for m in range(0, kern.N_MODES, 2):  # odd orders 1, 3
                order = m + 1
                omega2 = (order * math.pi / ell) ** 2 * stand.preload_tension_n / p[kern.P_MU]
                arest[span * kern.N_MODES + m] = 4 * gp / (order * math.pi) / omega2
    if "fibre_pulley_jump" in e:
        v = e["fibre_pulley_jump"]
        p[kern.P_PJ_ON] = 1.0
        p[kern.P_STEP], p[kern.P_THR], p[kern.P_TAUS] = v["step_m"], v["threshold_m"], v["tau_s"]
        p[kern.P_SEATS], p[kern.P_SHARE] = v["seats"], v["drive_share"]
    if "pulley_inertia_friction" in e:
        v = e["pulley_inertia_friction"]
        r = stand.pulley_radius_m
        if v["inertia_kg_m2"] <= 0:
            if v["kinetic_torque_n_m"] > 0 or v["viscous_n_m_s"] > 0:
                raise ValueError("pulley_inertia_friction: bearing friction needs inertia > 0")
        else:
            p[kern.P_PI_ON] = 1.0
            p[kern.P_MP] = v["inertia_kg_m2"] / r**2
            p[kern.P_FK] = v["kinetic_torque_n_m"] / r
            p[kern.P_FS] = p[kern.P_FK] * (1 + v["breakaway_ratio"])
            p[kern.P_CV] = v["viscous_n_m_s"] / r**2
    if "stick_slip_friction" in e:
        v = e["stick_slip_friction"]
        p[kern.P_SS_ON] = 1.0
        p[kern.P_RATIO], p[kern.P_VS] = v["static_excess"], v["stribeck_speed_m_s"]
        p[kern.P_EXP] = v["stribeck_exponent"]
    if "side_load_friction" in e:
        v = e["side_load_friction"]
        p[kern.P_SL_ON] = 1.0
        p[kern.P_MUW], p[kern.P_PEXP] = v["wall_mu"], v["exponent"]
    fill_outside(p, stand, e)
    return p, arest


def simulate(
    stand: StandParams,
    effects: Mapping[str, Mapping[str, float]],
    x_m: FloatArray,
    rate_hz: float,
    oversample: int = OVERSAMPLE,
    substeps: int = SUBSTEPS,
) -> OtherRun:
    """One run from static rest with the drive at x_m[0] (x down positive, m).

    Raises ValueError on an unknown effect or parameter, or a drive series that is not a
    finite 1-D series of at least two samples.
    """
    x = np.ascontiguousarray(x_m, dtype=np.float64)
    if x.ndim != 1 or x.size < 2 or not np.all(np.isfinite(x)):
        raise ValueError("the drive series must be finite, 1-D, with at least two samples")
    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise ValueError(f"rate must be > 0 Hz, got {rate_hz:g}")
    full = check_effects(effects)
    p, arest = parameter_row(stand, full)
    tab_x, tab_c = _friction_pieces(stand)
    res = kern.simulate_kernel(x - x[0], float(rate_hz), int(oversample), int(substeps), p,
                            tab_x, tab_c, arest)  # fmt: skip
    measured = {k: v for k, v in full.items() if ALL_EFFECTS[k].kind == "measurement"}
    u_rec, f_rec = record(res[0], res[2], rate_hz, oversample, measured)
    every = slice(None, None, oversample)
    return OtherRun(
        t_s=np.arange(x.size) / rate_hz,
        x_m=x,
        u_m=u_rec,
        force_n=f_rec,
        true_u_m=np.ascontiguousarray(res[0, every]),
        true_force_n=np.ascontiguousarray(res[2, every]),
        weight_force_n=np.ascontiguousarray(res[3, every]),
        seat_m=np.ascontiguousarray(res[4, every]),
        preload_tension_n=stand.preload_tension_n,
    )
