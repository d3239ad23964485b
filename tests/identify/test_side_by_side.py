"""Traces and lanes side by side: the threads live for one call, and the numbers stay."""

from __future__ import annotations

import threading
import time

import numba
import numpy as np
import pytest

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import StandConfig
from sim.effects import EffectSpec
from sim.identify import fitting, intervals
from sim.identify.fitting import Candidate, fit
from sim.identify.intervals import estimator_spread
from sim.identify.side_by_side import in_lanes, side_by_side
from sim.identify.traces import Trace, make_trace
from sim.model import Model, in_serial_lane

TWO_THREADS = pytest.mark.skipif(
    numba.get_num_threads() < 2, reason="one numba thread runs every item in turn"
)


def _trace_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name.startswith("trace")]


def _lane_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name.startswith("lane")]


@pytest.mark.skipif(numba.get_num_threads() < 2, reason="one numba thread runs items in turn")
def test_the_threads_of_a_call_are_gone_when_it_returns() -> None:
    seen: list[str] = []

    def work(k: int, serial: bool) -> int:
        seen.append(threading.current_thread().name)
        return k * k

    assert _trace_threads() == []
    for _ in range(3):  # each call starts its own threads and joins them
        assert side_by_side(work, [1, 3, 2]) == [0, 1, 4]
        assert _trace_threads() == []
    assert all(name.startswith("trace") for name in seen)


def test_a_failing_item_raises_in_the_caller_and_leaves_no_thread() -> None:
    def work(k: int, serial: bool) -> int:
        if k == 1:
            raise ValueError(f"item {k} failed")
        return k

    with pytest.raises(ValueError, match="item 1 failed"):
        side_by_side(work, [2, 2])
    assert _trace_threads() == []


@TWO_THREADS
def test_lanes_keep_the_order_run_serial_and_start_no_threads_of_their_own() -> None:
    def work(k: int) -> tuple[int, str, bool, list[tuple[int, bool]]]:
        # Inside a lane, traces side by side run in turn on the lane, serial.
        inner = side_by_side(lambda j, serial: (j, serial), [3, 1])
        assert _trace_threads() == []
        return k, threading.current_thread().name, in_serial_lane(), inner

    assert not in_serial_lane()
    results = in_lanes(work, [1.0, 5.0, 2.0, 4.0])
    assert [r[0] for r in results] == [0, 1, 2, 3]
    assert all(name.startswith("lane") and serial for _, name, serial, _ in results)
    assert all(inner == [(0, True), (1, True)] for *_, inner in results)
    assert _lane_threads() == [] and not in_serial_lane()


def test_a_lane_inside_a_lane_runs_in_turn_and_a_failure_reaches_the_caller() -> None:
    def inner(k: int) -> str:
        return threading.current_thread().name

    outer = in_lanes(lambda k: in_lanes(inner, [1.0, 1.0]), [1.0, 1.0])
    assert all(len(set(names)) == 1 for names in outer)  # each on its own lane's thread

    def failing(k: int) -> int:
        if k == 2:
            raise ValueError(f"lane {k} failed")
        return k

    with pytest.raises(ValueError, match="lane 2 failed"):
        in_lanes(failing, [1.0, 1.0, 1.0])
    assert _lane_threads() == []


@TWO_THREADS
def test_a_failing_lane_stops_the_running_ones_at_their_next_run(stand: StandConfig) -> None:
    # A refit that fails, Ctrl-C or SIGTERM must not wait for the other lanes' whole
    # refits: each running lane stops at its next simulation.
    trace = _trace(stand, [], 1)
    nominal = stand.stand_params("final", 3.096)
    base = Candidate.build()
    z = np.array([p.to_internal(1.0) if p.name != "friction_scale" else 1.0 for p in base.params])
    runs_done = [0, 0]

    def work(k: int) -> int:
        if k == 0:
            time.sleep(0.3)  # the other lane is simulating by now
            raise RuntimeError("the refit failed")
        for _ in range(400):  # seconds of simulations, were it not stopped
            fitting.Objective(base, [trace], nominal).residuals_batch(z[None])
            runs_done[k] += 1
        return k

    with pytest.raises(RuntimeError, match="the refit failed"):
        in_lanes(work, [2.0, 1.0])
    assert 0 < runs_done[1] < 400
    assert _lane_threads() == []


@TWO_THREADS
def test_a_failing_lane_cancels_the_pieces_not_yet_started() -> None:
    # A refit that fails (or Ctrl-C) must not wait for every other candidate's refit.
    ran: list[int] = []

    def work(k: int) -> int:
        if k == 0:
            raise RuntimeError("the first piece failed")
        time.sleep(0.05)
        ran.append(k)
        return k

    with pytest.raises(RuntimeError, match="first piece failed"):
        in_lanes(work, [2.0] + [1.0] * 29)  # the first piece starts first
    assert len(ran) < 10
    assert _lane_threads() == []


def _trace(stand: StandConfig, effects: list[EffectSpec], seed: int) -> Trace:
    signal = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=3, ramp_fraction=0.4)
    t, x = plan_motion(signal, stand.drive).sample(stand.sample_rate_hz)
    run = Model(stand.stand_params("final", 3.096), effects).run(x, stand.sample_rate_hz)
    rng = np.random.default_rng(seed)
    u = run.u_m + rng.normal(0.0, 2e-6, x.size)
    f = run.force_n + rng.normal(0.0, 0.05, x.size)
    return make_trace(f"quick{seed}", t, x, u, f, 3.096)


@TWO_THREADS
def test_fits_in_lanes_give_the_numbers_of_one_after_the_other(
    stand: StandConfig, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The baseline's starts and the bootstrap replicates run side by side; the serial
    # kernels compute every item as the parallel ones, so nothing may change.
    traces = [_trace(stand, [EffectSpec("fibre_viscoelastic")], seed) for seed in (1, 2)]
    nominal = stand.stand_params("final", 3.096)
    branch = Candidate.build("fibre_viscoelastic")

    def both() -> tuple[fitting.FitResult, dict[str, np.ndarray]]:
        base = fit(Candidate.build(), traces, nominal)
        spread, _ = estimator_spread(branch, {**base.values, **branch.natural(
            np.array([p.to_internal(0.5 * (p.low + p.high)) for p in branch.params])
        )}, traces, nominal, replicates=2)  # fmt: skip
        return base, spread

    laned = both()

    def in_turn(work, sizes):  # type: ignore[no-untyped-def]
        return [work(k) for k in range(len(sizes))]

    monkeypatch.setattr(fitting, "in_lanes", in_turn)
    monkeypatch.setattr(intervals, "in_lanes", in_turn)
    alone = both()
    assert laned[0].values == alone[0].values
    assert laned[0].train_cost == alone[0].train_cost
    assert laned[0].evaluations == alone[0].evaluations
    assert laned[1].keys() == alone[1].keys() and laned[1]
    for name in laned[1]:
        np.testing.assert_array_equal(laned[1][name], alone[1][name])
