"""A tenth effect in one file (tests/effects/weight_viscous_damping.py): registered, it runs
through the model (a kernel composed with its force) and is named by a diagnosis."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.checks.check import DRIVE_NOISE_M, SMALL_CAMPAIGN
from sim.config import StandConfig
from sim.effects import EFFECTS, EffectError, EffectSpec, parse_effect, register, unregister
from sim.effects.info import EffectInfo
from sim.effects.realism import MeasurementNoise, NoiseSpec, draw_real_stand
from sim.identify import diagnose, make_trace
from sim.model import Model
from tests.effects import weight_viscous_damping

NAME = "weight_viscous_damping"
MASS = 8.131


@pytest.fixture(scope="module")
def added(tmp_path_factory: pytest.TempPathFactory) -> Iterator[EffectInfo]:
    cache = tmp_path_factory.mktemp("kernels")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("LABSTAND_KERNEL_CACHE", str(cache))
        info = register(weight_viscous_damping.INFO)
        try:
            yield info
        finally:
            unregister(NAME)


def _slow_ramp(stand: StandConfig) -> np.ndarray:
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.02, 0.125, cycles=1, ramp_fraction=0.4)
    _, x = plan_motion(spec, stand.drive).sample(stand.sample_rate_hz)
    return x


def test_registering_gives_it_free_kernel_columns_and_a_name(added: EffectInfo) -> None:
    assert EFFECTS[NAME] is added
    builtin = [c for e in EFFECTS.values() if e is not added for c in (e.flag_column,)]
    builtin += [p.column for e in EFFECTS.values() if e is not added for p in e.params]
    ours = [added.flag_column, *(p.column for p in added.params)]
    assert not set(ours) & set(builtin)
    assert parse_effect(f"{NAME}:damping_n_s_m=30").resolved() == {"damping_n_s_m": 30.0}
    with pytest.raises(EffectError, match="already registered"):
        register(weight_viscous_damping.INFO)
    with pytest.raises(EffectError, match="cannot be removed"):
        unregister("fibre_viscoelastic")
    too_big = dataclasses.replace(added, name="too_big", params=added.params * 8)
    with pytest.raises(EffectError, match="no room"):
        register(too_big)
    assert "too_big" not in EFFECTS


def test_its_force_enters_the_weights_balance(stand: StandConfig, added: EffectInfo) -> None:
    # On a slow constant-speed pull the weight moves steadily: n·T = G + friction + b·v,
    # so the damping raises the tension by b·v/n over the same run without it (on
    # average: the undamped run still rings at the fibre's frequency, ≈ 10 Hz).
    x = _slow_ramp(stand)
    params = stand.stand_params("final", MASS)
    b = 200.0
    plain = Model(params).run(x, stand.sample_rate_hz)
    damped = Model(params, [EffectSpec(NAME, {"damping_n_s_m": b})]).run(x, stand.sample_rate_hz)
    rate = stand.sample_rate_hz
    ramp = slice(int(1.5 * rate), int(3.0 * rate))  # mid-ramp, its start's ringing gone
    v = damped.v_m_s[ramp]
    assert np.all(v > 1e-3)  # moving steadily up the incline
    expected = b * v / params.projection
    rise = damped.force_n[ramp] - plain.force_n[ramp]
    assert rise.mean() == pytest.approx(expected.mean(), rel=0.03)
    # At zero damping the composed kernel is the kernel: bit for bit.
    zero = Model(params, [EffectSpec(NAME, {"damping_n_s_m": 0.0})]).run(x, rate)
    np.testing.assert_array_equal(zero.force_n, plain.force_n)


def test_the_composed_kernel_is_written_once_and_reused(
    stand: StandConfig, added: EffectInfo
) -> None:
    from os import environ

    params = stand.stand_params("final", MASS)
    x = _slow_ramp(stand)[:400]
    for b in (10.0, 20.0):  # two models of the same set of effects
        Model(params, [EffectSpec(NAME, {"damping_n_s_m": b})]).run(x, stand.sample_rate_hz)
    files = sorted(Path(environ["LABSTAND_KERNEL_CACHE"]).glob("composed_*.py"))
    sets = [f.read_text().split("\n# numba")[0].rsplit("composed for:", 1)[1] for f in files]
    # The runs composed one kernel with this effect, however many models they built
    # (here and in the tests before); no set of effects is ever written twice (composed
    # kernels are memoised per process), whatever other tests composed before.
    assert len([s for s in sets if NAME in s]) == 1
    assert len(sets) == len(set(sets))


def test_a_diagnosis_names_it(stand: StandConfig, added: EffectInfo) -> None:
    rng = np.random.default_rng(5)
    real = draw_real_stand(stand.stand_params("final", MASS), rng)
    truth = [EffectSpec(NAME, {"damping_n_s_m": 25.0})]
    traces = []
    for name, signal in SMALL_CAMPAIGN:
        t, x = plan_motion(signal, stand.drive).sample(stand.sample_rate_hz)
        run = Model(real, truth).run(x, stand.sample_rate_hz)
        u, f = MeasurementNoise(NoiseSpec(), stand.sample_rate_hz, rng).apply(run.u_m, run.force_n)
        x_rec = x + rng.normal(0.0, DRIVE_NOISE_M, x.size)
        traces.append(make_trace(name, t, x_rec, u, f, MASS))
    candidates = [NAME, "side_load_friction", "fibre_viscoelastic"]
    result = diagnose(traces, stand.stand_params("final", MASS), candidates)
    assert result.effect == NAME, [(r.effect, r.p_value) for r in result.ranking]
    assert result.effects[0].params["damping_n_s_m"] == pytest.approx(25.0, rel=0.3)
    assert result.effects[0].closure > 0.5
