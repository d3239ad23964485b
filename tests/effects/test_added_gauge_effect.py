"""A gauge effect from one file (tests/effects/force_gain_drift.py): registered, it ends
the model's gauge chain in every kind of run, its inverse restarts segments, off it
changes no number, a mistake in it is one line, and a diagnosis names it."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import StandConfig
from sim.effects import EFFECTS, EffectError, EffectSpec, register, unregister
from sim.effects.info import EffectInfo
from sim.model import Model, Restarts
from sim.physics import compose, gauges, layout, runs
from tests.effects import force_gain_drift
from tests.effects.blind import named_blind

NAME = "force_gain_drift"
MASS = 8.131
DRIFT = 5.0e-3  # 1/s


@pytest.fixture(scope="module")
def drift() -> Iterator[EffectInfo]:
    info = register(force_gain_drift.INFO)
    try:
        yield info
    finally:
        unregister(NAME)


def _drive(stand: StandConfig) -> np.ndarray:
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.02, 1.0, cycles=2, ramp_fraction=0.4)
    _, x = plan_motion(spec, stand.drive).sample(stand.sample_rate_hz)
    return x


def _on(value: float = DRIFT) -> EffectSpec:
    return EffectSpec(NAME, {"drift_per_s": value})


def test_its_parameter_gets_a_column_and_it_leaves_the_dynamics_alone(
    stand: StandConfig, drift: EffectInfo
) -> None:
    assert EFFECTS[NAME] is drift
    assert layout.R_X <= drift.flag_column < drift.params[0].column < layout.N_ROW
    params = stand.stand_params("final", MASS)
    row = runs.parameter_row(params, [_on()])
    assert row[drift.params[0].column] == DRIFT
    assert row[layout.R_X_ON] == 0.0  # no added force: the dynamics' switch stays off
    assert runs._kernel(row) is compose.baseline()  # alone, the baseline runs
    with pytest.raises(EffectError, match="already registered"):
        register(force_gain_drift.INFO)


def test_the_recorded_force_is_the_true_one_times_its_gain_in_every_run(
    stand: StandConfig, drift: EffectInfo
) -> None:
    params = stand.stand_params("final", MASS)
    x, rate = _drive(stand), stand.sample_rate_hz
    t = np.arange(x.size) / rate
    run = Model(params, [_on()]).run(x, rate)
    np.testing.assert_allclose(run.force_n, (1.0 + DRIFT * t) * run.true_force_n, rtol=1e-14)
    np.testing.assert_array_equal(run.u_m, run.true_u_m)
    # After the built-in chain (the gauge's low-pass, the dial gauge's scale): its last stage.
    builtin = [EffectSpec("force_gauge_dynamics"), EffectSpec("dial_gauge_calibration")]
    chained = Model(params, [*builtin, _on()]).run(x, rate)
    alone = Model(params, builtin).run(x, rate)
    np.testing.assert_allclose(chained.force_n, (1.0 + DRIFT * t) * alone.force_n, rtol=1e-14)
    np.testing.assert_array_equal(chained.u_m, alone.u_m)
    # A batch, row by row: the same numbers; a stream, block by block: the same to the
    # rounding the built-in low-pass shows in a stream (tests/effects/test_simulator.py).
    model = Model(params, [*builtin, _on()])
    batch = model.run_batch(x, rate, [{}, {f"{NAME}.drift_per_s": 2 * DRIFT}])
    np.testing.assert_array_equal(batch.force_n[0], chained.force_n)
    np.testing.assert_allclose(batch.force_n[1], (1.0 + 2 * DRIFT * t) * alone.force_n, rtol=1e-14)
    stream = model.stream(rate, x0_m=float(x[0]))
    blocks = [stream.advance(block)[1] for block in np.array_split(x[1:], 7)]
    np.testing.assert_allclose(np.concatenate(blocks), chained.force_n[1:], rtol=0, atol=1e-9)


def test_restarts_undo_it_and_segments_keep_the_recordings_clock(
    stand: StandConfig, drift: EffectInfo
) -> None:
    params = stand.stand_params("final", MASS)
    x, rate = _drive(stand), stand.sample_rate_hz
    t = np.arange(x.size) / rate
    model = Model(params, [EffectSpec("force_gauge_dynamics"), _on()])
    run = model.run(x, rate)
    # The inverse in closed form: F = F_rec/(1 + r·t), the true force again.
    row = runs.parameter_row(params, model.effects)
    on = [info for info in EFFECTS.values() if row[info.flag_column] > 0]
    plain = Model(params, [EffectSpec("force_gauge_dynamics")]).run(x, rate)
    _, _, back = gauges.true_channels(row, on, rate, run.u_m, run.v_m_s, run.force_n, np.nan)
    np.testing.assert_allclose(back, run.force_n / (1.0 + DRIFT * t), rtol=1e-15)
    np.testing.assert_allclose(back, plain.force_n, rtol=1e-12)
    # Segments restarted from the recorded channels record on the recording's clock
    # (t from its start, not the segment's) and their gauge starts from the true force:
    # they give what the drift-free model's segments give, times the gain.
    starts = np.arange(0, x.size - 400, 700, dtype=np.int64)
    lengths = np.full(starts.size, 400, dtype=np.int64)
    recorded = Restarts(starts, lengths, run.u_m, run.v_m_s, run.force_n)
    _, seg_f = model.run_segments(x, rate, recorded)
    truth = Restarts(starts, lengths, plain.u_m, plain.v_m_s, plain.force_n)
    _, plain_f = Model(params, [EffectSpec("force_gauge_dynamics")]).run_segments(x, rate, truth)
    gain = 1.0 + DRIFT * (starts[:, None] + np.arange(400)) / rate
    np.testing.assert_allclose(seg_f[0], gain * plain_f[0], rtol=1e-12)


def test_off_it_changes_no_number(stand: StandConfig, drift: EffectInfo) -> None:
    params = stand.stand_params("final", MASS)
    x, rate = _drive(stand), stand.sample_rate_hz
    for others in ([], [EffectSpec("fibre_viscoelastic"), EffectSpec("channel_time_skew")]):
        base = Model(params, others).run(x, rate)
        zero = Model(params, [*others, _on(0.0)]).run(x, rate)
        np.testing.assert_array_equal(zero.force_n, base.force_n)
        np.testing.assert_array_equal(zero.u_m, base.u_m)
        np.testing.assert_array_equal(zero.true_force_n, base.true_force_n)
    # A row without it, in a batch where another row has it on: its numbers, bit for bit.
    rows = np.stack([runs.parameter_row(params, []), runs.parameter_row(params, [_on()])])
    batch = runs.simulate_rows(x - x[0], rate, rows, params.friction)
    np.testing.assert_array_equal(batch.force_n[0], Model(params).run(x, rate).force_n)


def _refused(**changes: Any) -> str:
    bad = dataclasses.replace(force_gain_drift.INFO, name="bad_gauge", **changes)
    with pytest.raises(EffectError) as refused:
        register(bad)
    assert "bad_gauge" not in EFFECTS
    message = str(refused.value)
    assert "\n" not in message and message.startswith("bad_gauge: ")
    return message


def test_a_mistake_in_its_file_is_refused_in_one_line() -> None:
    def raises(values: Any, t: Any, u: Any, f: Any) -> Any:
        return u, f * values[1]  # only one parameter: IndexError

    assert "fails on a trial run" in _refused(record=raises)
    assert "tuple of 2" in _refused(record=lambda v, t, u, f: f)
    assert "input's shape" in _refused(record=lambda v, t, u, f: (u, f[:-1]))
    wrong = lambda v, t, u, vv, f: (u, vv, f * (1 + v[0] * t))  # noqa: E731 (the forward)
    assert "does not give back the true force" in _refused(invert=wrong)
    assert "kind 'measurement'" in _refused(kind="physical")
    assert "record (and invert) only" in _refused(carried=True, states=("G",))


@pytest.mark.parametrize(("mass", "seed"), [(MASS, 3), (20.0, 4)])
def test_a_diagnosis_names_it_among_every_effect(
    stand: StandConfig, drift: EffectInfo, mass: float, seed: int
) -> None:
    result, truth = named_blind(stand, NAME, mass, seed)
    fitted = result.effects[0].params["drift_per_s"]
    assert fitted == pytest.approx(truth["drift_per_s"], rel=0.05)
    assert result.effects[0].closure > 0.5  # most of the gap: the rest is the gauges' noise
