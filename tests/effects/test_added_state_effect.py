"""A tenth effect with a state and a switch, in one file (tests/effects/weight_latch.py):
registered, its hooks are composed into the model like the built-in terms', its physics
holds, off it changes no number, and a diagnosis names it."""

from __future__ import annotations

import dataclasses
import importlib
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import StandConfig
from sim.effects import EFFECTS, EffectError, EffectSpec, register, unregister
from sim.effects.info import EffectInfo
from sim.model import Model
from sim.physics import compose, layout
from sim.physics.runs import friction_arrays, parameter_row, simulate_rows
from tests.effects import weight_latch
from tests.effects.blind import named_blind

NAME = "weight_latch"
MASS = 8.131


@pytest.fixture(scope="module")
def latch() -> Iterator[EffectInfo]:
    info = register(weight_latch.INFO)
    try:
        yield info
    finally:
        unregister(NAME)


def test_registering_places_its_columns_state_and_slot(latch: EffectInfo) -> None:
    assert EFFECTS[NAME] is latch
    assert layout.R_X <= latch.flag_column < latch.params[-1].column < layout.N_ROW
    assert layout.S_X <= latch.slot_index < layout.S_X + layout.N_SX
    names = layout.constants(layout.TERMS, (latch,))
    # Its state follows the union's; its names are what its hooks read.
    assert names["Y_LT_F"] == len(layout.STATES) == names["NY"] - 1
    assert names["S_LT_COIL"] == latch.slot_index
    assert names["R_LT_TAU"] == latch.param("tau_s").column
    source = compose.source_for(layout.TERMS, (latch,))
    rhs = source[source.index("def _rhs(") : source.index("def _set_taut(")]
    assert "drive += y[Y_LT_F]" in rhs  # its force, written in place
    assert "lt_weight(" not in rhs
    with pytest.raises(EffectError, match="already registered"):
        register(weight_latch.INFO)


def _refusal(tmp_path: Path, name: str, body: str, **info: object) -> str:
    """The message ``register`` refuses a one-file effect with this hook text."""
    (tmp_path / f"{name}.py").write_text("from numba import njit\n\n" + body)
    sys.path.insert(0, str(tmp_path))
    try:
        importlib.import_module(name)
        fields = {"terms": name, "states": ("F",), "symbol": "QQ", **info}
        bad = dataclasses.replace(weight_latch.INFO, name=name, **fields)  # type: ignore[arg-type]
        with pytest.raises(EffectError) as refused:
            register(bad)
        assert name not in EFFECTS
        assert "\n" not in str(refused.value)  # one line
        return str(refused.value)
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop(name, None)


def test_a_file_the_model_cannot_compose_is_refused_in_one_line(tmp_path: Path) -> None:
    njit = '@njit(cache=True, error_model="numpy")\n'
    rates = f"{njit}def qq_rates(c, y, sg, t1, t2, zd):\n    return (0.0,)\n"
    message = _refusal(tmp_path, "typo", rates.replace("qq_rates", "qq_rate"))
    assert "qq_rate is no hook" in message
    early = f"{njit}def qq_rates(c, y, sg, t1, t2, zd):\n    if c[0] > 0:\n        return (1.0,)\n"
    assert "return once" in _refusal(tmp_path, "early", early + "    return (0.0,)\n")
    assert "must take" in _refusal(tmp_path, "args", rates.replace("zd)", "z)"))
    assert "must be compiled" in _refusal(tmp_path, "plain", rates.replace(njit, ""))
    pack = f"{njit}def qq_pack(c, osc, osc_exp, real):\n    return osc, osc_exp, real\n"
    assert "need qq_rates" in _refusal(tmp_path, "norates", pack)
    assert "symbol VE is taken" in _refusal(tmp_path, "taken", rates, symbol="VE")


def _up_and_down(stand: StandConfig) -> np.ndarray:
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.03, 0.25, cycles=1, ramp_fraction=0.4)
    _, x = plan_motion(spec, stand.drive).sample(stand.sample_rate_hz)
    return x


def test_the_pull_settles_as_its_closed_form_and_the_switch_flips_at_its_heights(
    stand: StandConfig, latch: EffectInfo
) -> None:
    # Sample by sample through the composed model, reading the state f and the switch.
    params = stand.stand_params("final", MASS)
    force, tau, h, band = 8.0, 0.08, 0.02, 0.002
    spec = EffectSpec(NAME, {"force_n": force, "tau_s": tau, "height_m": h, "band_m": band})
    row = parameter_row(params, [spec])
    model = compose.kernel_for(layout.TERMS, (latch,))
    c = model.pack(row, *friction_arrays(params.friction))
    state = np.array(model.rest_state(c))
    x = _up_and_down(stand)
    x = x - x[0]
    dt = 1.0 / stand.sample_rate_hz
    n = x.size
    u, f, coil, tension = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    out = [np.zeros(2) for _ in range(4)]
    for i in range(1, n):
        model.advance_into(x[i - 1 : i + 1], dt, 1, c, state, *out)
        u[i], f[i], coil[i], tension[i] = state[0], state[-1], c[latch.slot_index], out[2][1]
    # Sample by sample is one run, bit for bit (the switch and f carry over in c, state).
    whole = Model(params, [spec]).run(x, stand.sample_rate_hz)
    np.testing.assert_array_equal(u[1:], whole.true_u_m[1:])
    np.testing.assert_array_equal(tension[1:], whole.true_force_n[1:])
    flips = np.flatnonzero(np.diff(coil)) + 1
    assert flips.size == 2  # on once on the way up, off once on the way down
    on, off = flips
    assert coil[on] == 1.0 and u[on - 1] < h <= u[on]
    assert coil[off] == 0.0 and u[off - 1] >= h - band > u[off]
    assert np.all(f[:on] == 0.0)
    # While on: f = F + (f_on − F)·e^(−(t − t_on)/τ); then from f_off toward 0.
    t = np.arange(n) * dt
    rising = force + (f[on] - force) * np.exp(-(t[on:off] - t[on]) / tau)
    np.testing.assert_allclose(f[on:off], rising, rtol=1e-9)
    falling = f[off] * np.exp(-(t[off:] - t[off]) / tau)
    np.testing.assert_allclose(f[off:], falling, rtol=1e-9, atol=1e-12)
    # It acts on the weight: at the end of the top dwell (weight at rest, settled pull)
    # the fibre carries f/n less than without the magnet.
    plain = Model(params).run(x, stand.sample_rate_hz)
    settled = np.flatnonzero(x == x.max())[-1]  # the last sample of the top dwell
    drop = (plain.true_force_n[settled] - tension[settled]) * params.projection
    assert f[settled] > 0.99 * force
    assert drop == pytest.approx(f[settled], rel=0.02)


def test_off_it_changes_no_number(stand: StandConfig, latch: EffectInfo) -> None:
    params = stand.stand_params("final", MASS)
    x = _up_and_down(stand)
    rate = stand.sample_rate_hz
    # At zero pull the model composed with it is the baseline, bit for bit.
    plain = Model(params).run(x, rate)
    zero = Model(params, [EffectSpec(NAME, {"force_n": 0.0})]).run(x, rate)
    np.testing.assert_array_equal(zero.force_n, plain.force_n)
    np.testing.assert_array_equal(zero.u_m, plain.u_m)
    # A row without it, in a batch composed with it (another row has it on), gives the
    # union's numbers for a built-in effect, bit for bit.
    others = [EffectSpec("fibre_viscoelastic"), EffectSpec("fibre_pulley_jump")]
    rows = np.stack(
        [parameter_row(params, others), parameter_row(params, [*others, EffectSpec(NAME)])]
    )
    batch = simulate_rows(x - x[0], rate, rows, params.friction)
    union = Model(params, others).run(x, rate)
    np.testing.assert_array_equal(batch.true_force_n[0], union.true_force_n)
    np.testing.assert_array_equal(batch.true_u_m[0], union.true_u_m)
    assert not np.array_equal(batch.true_force_n[1], batch.true_force_n[0])


@pytest.mark.parametrize(("mass", "seed"), [(MASS, 3), (20.0, 4)])
def test_a_diagnosis_names_it_among_every_effect(
    stand: StandConfig, latch: EffectInfo, mass: float, seed: int
) -> None:
    result, truth = named_blind(stand, NAME, mass, seed)
    fitted = result.effects[0].params
    assert fitted["force_n"] == pytest.approx(truth["force_n"], rel=0.05)
    assert fitted["tau_s"] == pytest.approx(truth["tau_s"], rel=0.15)
    assert result.effects[0].closure > 0.9  # it explains the gap
