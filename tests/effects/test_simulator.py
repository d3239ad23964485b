"""The model with effects: equal to the baseline with effects off, consistent across its
entry points (single, batch, stream), accurate, and at rest when nothing moves."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec
from sim.config import StandConfig
from sim.effects import EFFECTS, EffectError, EffectSpec
from sim.model import Model
from sim.physics import compose, layout
from sim.physics.runs import Stream, friction_arrays, parameter_row
from sim.situations import SITUATIONS
from tests.effects.helpers import RATE, signal_drive, situation_drive

ALL = [EffectSpec(name) for name in EFFECTS]
PHYSICAL = [EffectSpec(n) for n, info in EFFECTS.items() if info.kind == "physical"]

#: Every effect at zero magnitude (where it has one): exactly the baseline.
ZERO_MAGNITUDE = [
    EffectSpec("fibre_viscoelastic", {"branch_stiffness_n_m": 0.0}),
    EffectSpec("fibre_transverse_vibration", {"load_scale": 0.0}),
    EffectSpec("fibre_pulley_jump", {"step_m": 0.0}),
    EffectSpec("side_load_friction", {"friction_coeff": 0.0}),
    EffectSpec("dial_gauge_calibration", {"gain_error": 0.0, "offset_m": 0.0}),
    EffectSpec("channel_time_skew", {"force_skew_s": 0.0, "displacement_skew_s": 0.0}),
]


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


@pytest.mark.parametrize("params", ["starting", "final"])
@pytest.mark.parametrize("name", list(SITUATIONS))
def test_all_effects_off_reproduces_the_baseline(
    stand: StandConfig, name: str, params: str
) -> None:
    x, mass = situation_drive(stand, name)
    p = stand.stand_params(params, mass)
    base = Model(p).run(x, RATE)  # the model composed without terms
    n = x.size
    u, v, t1, t2 = (np.empty(n) for _ in range(4))
    most = compose.union().simulate_into(  # every term in, every effect off
        x - x[0], 1.0 / RATE, 1, parameter_row(p), *friction_arrays(p.friction), u, v, t1, t2
    )
    # Bit for bit: an effect switched off adds exact zeros, a term left out adds nothing.
    assert np.array_equal(u, base.u_m)
    assert np.array_equal(v, base.v_m_s)
    assert np.array_equal(t1, base.force_n)
    assert np.array_equal(t2, base.force_n)
    assert most == base.max_substeps == 1


@pytest.mark.parametrize("name", ["3", "11", "12a"])
def test_zero_magnitudes_reproduce_the_baseline(stand: StandConfig, name: str) -> None:
    x, mass = situation_drive(stand, name)
    p = stand.stand_params("final", mass)
    base = Model(p).run(x, RATE)
    for spec in [*ZERO_MAGNITUDE, None]:
        effects = ZERO_MAGNITUDE if spec is None else [spec]  # each alone, then all together
        run = Model(p, effects).run(x, RATE)
        assert _rel(run.u_m, base.u_m) <= 1e-9, spec
        assert _rel(run.force_n, base.force_n) <= 1e-9, spec


def test_massless_frictionless_pulley_tends_to_the_baseline(stand: StandConfig) -> None:
    # The pulley's DOF splits the fibre into two springs in series (k₁, k₂ ∝ 1/length);
    # with J → 0 and no bearing friction it must be the single fibre again.
    x, mass = situation_drive(stand, "10")
    p = stand.stand_params("final", mass)
    base = Model(p).run(x, RATE)
    light = EffectSpec(
        "pulley_inertia_friction",
        {"inertia_kg_m2": 1e-6, "bearing_torque_n_m": 0.0, "load_coeff": 0.0},
    )
    run = Model(p, [light]).run(x, RATE)
    span = np.ptp(base.force_n)
    assert np.abs(run.force_n - base.force_n).max() < 0.01 * span
    assert np.abs(run.u_m - base.u_m).max() < 0.01 * np.ptp(base.u_m)


@pytest.mark.parametrize("mass_kg", [3.096, 8.131])
@pytest.mark.parametrize("params", ["starting", "final"])
def test_static_rest_stays_at_rest_with_every_effect(
    stand: StandConfig, mass_kg: float, params: str
) -> None:
    p = stand.stand_params(params, mass_kg)
    run = Model(p, ALL).run(np.zeros(4000), RATE)
    assert np.abs(run.u_m).max() < 1e-12
    assert np.abs(run.true_u_m).max() < 1e-12
    assert np.allclose(run.force_n, p.preload_tension_n, rtol=1e-10)
    assert np.allclose(run.weight_force_n, p.preload_tension_n, rtol=1e-10)
    assert np.abs(run.v_m_s).max() < 1e-12


def test_batch_equals_single_runs_with_mixed_effects(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "10")
    p = stand.stand_params("final", mass)
    model = Model(p, ALL)
    variants = [
        {},
        {"stiffness_n_m": 30e3, "fibre_viscoelastic.relaxation_time_s": 0.01},
        {"friction_scale": 0.8, "pulley_inertia_friction.inertia_kg_m2": 5e-5},
    ]
    batch = model.run_batch(x, RATE, variants)
    for i, variant in enumerate(variants):
        one = model.variant(variant).run(x, RATE)
        assert np.array_equal(batch.u_m[i], one.u_m)
        assert np.array_equal(batch.force_n[i], one.force_n)
        assert np.array_equal(batch.true_force_n[i], one.true_force_n)
    # Without physical effects the batch runs on the baseline's kernel, gauge effects after.
    gauge = Model(p, [EffectSpec("force_gauge_dynamics")])
    batch = gauge.run_batch(x, RATE, [{}, {"force_gauge_dynamics.cutoff_hz": 50.0}])
    for i, variant in enumerate([{}, {"force_gauge_dynamics.cutoff_hz": 50.0}]):
        one = gauge.variant(variant).run(x, RATE)
        assert np.allclose(batch.force_n[i], one.force_n, rtol=0, atol=1e-9)
        assert np.allclose(batch.true_force_n[i], one.true_force_n, rtol=0, atol=1e-9)


def test_variants_change_parameters_by_name(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "10")
    p = stand.stand_params("final", mass)
    model = Model(p, [EffectSpec("dial_gauge_calibration")])
    res = model.run_batch(x, RATE, [{}, {"dial_gauge_calibration.gain_error": -0.03}])
    assert np.allclose(res.u_m[1], 0.97 * res.true_u_m[1], rtol=0, atol=1e-15)
    assert np.allclose(res.u_m[0], 1.02 * res.true_u_m[0], rtol=0, atol=1e-15)
    with pytest.raises(EffectError, match="has no effect 'fibre_viscoelastic'"):
        model.variant({"fibre_viscoelastic.relaxation_time_s": 0.01})
    with pytest.raises(EffectError, match="outside its admissible range"):
        model.variant({"dial_gauge_calibration.gain_error": 3.0})


def test_stream_equals_one_run_over_the_blocks(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "11")
    p = stand.stand_params("final", mass)
    effects = [*ALL[:-2], EffectSpec("channel_time_skew", {"displacement_skew_s": 0.7e-3}), ALL[-1]]
    offline = Model(p, effects).run(x, RATE)
    stream = Model(p, effects).stream(RATE, x0_m=float(x[0]))
    rng = np.random.default_rng(5)
    cuts = np.sort(rng.choice(np.arange(1, x.shape[0] - 1), size=40, replace=False))
    parts = [stream.advance(block) for block in np.split(x[1:], cuts)]
    u = np.concatenate([pu for pu, _ in parts])
    f = np.concatenate([pf for _, pf in parts])
    assert np.allclose(u, offline.u_m[1:], rtol=0, atol=1e-12)
    assert np.allclose(f, offline.force_n[1:], rtol=0, atol=1e-9)


def test_stream_refuses_to_record_a_channel_early(stand: StandConfig) -> None:
    skew = EffectSpec("channel_time_skew", {"force_skew_s": -1e-3})
    with pytest.raises(EffectError, match="negative skew"):
        Model(stand.stand_params("final"), [skew]).stream(RATE)


@pytest.mark.parametrize("name", ["10", "12a"])
def test_physical_effects_converge_with_the_step(stand: StandConfig, name: str) -> None:
    # Every physical effect on at once; eight times the substeps changes little.
    x, mass = situation_drive(stand, name)
    p = stand.stand_params("final", mass)
    coarse = Model(p, PHYSICAL).run(x, RATE)
    fine = Model(p, PHYSICAL, substeps=8).run(x, RATE)
    for a, b in ((coarse.u_m, fine.u_m), (coarse.force_n, fine.force_n)):
        assert np.linalg.norm(a - b) / np.linalg.norm(b - b.mean()) < 2e-3


def test_effects_given_twice_are_refused(stand: StandConfig) -> None:
    twice = [EffectSpec("fibre_viscoelastic"), EffectSpec("fibre_viscoelastic")]
    with pytest.raises(EffectError, match="given twice"):
        Model(stand.stand_params("final"), twice)


def test_the_simulated_stand_switches_effects_on_by_name(stand: StandConfig) -> None:
    from sim.hardware.stand_model import available_effects, build_stand_model

    assert set(EFFECTS) <= set(available_effects())
    p = stand.stand_params("final")
    model = build_stand_model(p, RATE, ["fibre_viscoelastic", "channel_time_skew"])
    assert isinstance(model, Stream)
    assert [e.name for e in model.effects] == ["fibre_viscoelastic", "channel_time_skew"]
    x, _ = situation_drive(stand, "10")
    _, f = model.advance(x[1:] - x[0])
    offline = Model(p, list(model.effects)).run(x - x[0], RATE)
    assert np.allclose(f, offline.force_n[1:], rtol=0, atol=1e-9)


def test_the_simulated_stand_takes_effect_parameters(stand: StandConfig) -> None:
    from sim.hardware.stand_model import build_stand_model

    p = stand.stand_params("final")
    model = build_stand_model(p, RATE, ["force_gauge_dynamics:cutoff_hz=40,damping_ratio=0.9"])
    assert isinstance(model, Stream)
    (spec,) = model.effects
    assert spec.resolved() == {"cutoff_hz": 40.0, "damping_ratio": 0.9}
    with pytest.raises(EffectError, match="unknown parameter 'cutoff'"):
        build_stand_model(p, RATE, ["force_gauge_dynamics:cutoff=40"])
    with pytest.raises(EffectError, match="given twice"):
        build_stand_model(p, RATE, ["channel_time_skew", "channel_time_skew:force_skew_s=0"])


@pytest.mark.parametrize("rate_h", [0.0, 1e-7, 0.3, 0.999, 1.001, 7.0, 60.0])
def test_the_exponential_step_is_exact_for_a_forced_linear_decay(rate_h: float) -> None:
    # ẏ = −λy + b: ETDRK4 integrates the decay exactly and keeps the fixed point b/λ,
    # on both sides of the switch from φ's series to its closed form (λh = 1); λ = 0 is
    # RK4's own step, exact for a constant rate.
    h, b, y0 = 1e-4, 3.0, -0.7
    lam = rate_h / h
    e2, half, e, b1, b2, b4 = compose.union()._etd_weights(lam, h)
    n1 = b  # N = ẏ + λy = b at every stage
    ya = e2 * y0 + half * n1
    yc = e2 * ya + half * (2.0 * b - n1)
    y1 = e * y0 + b1 * n1 + b2 * (b + b) + b4 * b
    exact = y0 + b * h if lam == 0.0 else b / lam + (y0 - b / lam) * np.exp(-lam * h)
    half_exact = y0 + b * h / 2 if lam == 0.0 else b / lam + (y0 - b / lam) * np.exp(-lam * h / 2)
    assert y1 == pytest.approx(exact, rel=1e-12, abs=1e-15)
    assert ya == pytest.approx(half_exact, rel=1e-12, abs=1e-15)
    assert np.isfinite(yc)


@pytest.mark.parametrize(
    ("name", "effect", "damping"),
    [
        ("11", EffectSpec("pulley_inertia_friction", {"inertia_kg_m2": 1e-5}), 4.0),
        ("12a", EffectSpec("pulley_inertia_friction", {"inertia_kg_m2": 3e-5}), 4.0),
        ("11", EffectSpec("stick_slip_friction", {"bristle_stiffness_n_m": 1e6}), 1.0),
        (
            "12a",
            EffectSpec(
                "stick_slip_friction",
                {"bristle_stiffness_n_m": 1e6, "stribeck_speed_m_s": 0.03, "static_ratio": 1.0},
            ),
            1.0,
        ),
    ],
)
def test_stiff_decays_take_few_substeps_and_stay_accurate(
    stand: StandConfig, name: str, effect: EffectSpec, damping: float
) -> None:
    # A light pulley's rim between two damped segments decays at (c₁ + c₂)·r²/J, ~1e5/s,
    # and a stiff LuGre bristle relaxes at σ₀|v|/g as fast; RK4 needed |λ|h ≤ 1.5 for
    # them (tens of substeps per sample). Integrated exactly (ETDRK4), the step follows
    # the slower dynamics, and the force stays within 0.03 N of a 64-substep run (RK4
    # limited by the rim's oscillation alone errs 0.017 N; the gauge's noise is 0.02 N).
    x, mass = situation_drive(stand, name)
    p = stand.stand_params("final", mass)
    p = dataclasses.replace(p, damping_n_s_m=p.damping_n_s_m * damping)
    run = Model(p, [effect]).run(x, RATE)
    fine = Model(p, [effect], substeps=compose.union().NSUB_MAX).run(x, RATE)
    assert np.abs(run.force_n - fine.force_n).max() < 0.03
    assert np.abs(run.u_m - fine.u_m).max() < 1e-6
    c = compose.union().pack(parameter_row(p, [effect]), *friction_arrays(p.friction))
    if effect.name == "pulley_inertia_friction":
        decay = c[layout.E_RIM]
    else:  # the bristle's relaxation at the run's top speed
        speed = float(np.abs(run.v_m_s).max())
        decay = c[layout.D_SIG0] * speed / (c[layout.P_FRICTION_N] * compose.union()._mu(speed, c))
    assert run.max_substeps <= 0.5 * np.ceil(decay / RATE / 1.5)


def test_a_stiff_bristle_steps_by_how_fast_its_rate_changes_not_by_its_size(
    stand: StandConfig,
) -> None:
    # The exponential step is exact for a frozen relaxation rate σ₀|v|/g(v); what it
    # misses is the rate's change within the step. Away from reversals that change is
    # small (|a|/|v| per second), so a heavy weight's 2 Hz trapezoid at σ₀ 1e6 N/m takes
    # fewer substeps than a quarter of the rate itself asked (the bound near reversals),
    # with the force as close to a 64-substep run.
    p = stand.stand_params("final", 8.131)
    effect = EffectSpec("stick_slip_friction", {"bristle_stiffness_n_m": 1e6})
    x = signal_drive(stand, SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=3, ramp_fraction=0.4))
    run = Model(p, [effect]).run(x, RATE)
    fine = Model(p, [effect], substeps=compose.union().NSUB_MAX).run(x, RATE)
    assert np.abs(run.force_n - fine.force_n).max() < 0.03
    assert np.abs(run.u_m - fine.u_m).max() < 1e-6
    c = compose.union().pack(parameter_row(p, [effect]), *friction_arrays(p.friction))
    speed = float(np.abs(run.v_m_s).max()) + 0.05
    quarter = (
        c[layout.D_SIG0] * speed / (c[layout.P_FRICTION_N] * compose.union()._mu(speed, c)) / 4.0
    )
    assert run.max_substeps <= 0.5 * np.ceil(quarter / RATE / 1.5)
