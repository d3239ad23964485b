"""Benchmark: real-time factor of the baseline model against scipy's solve_ivp.

Side by side in one run, on the same machine and the same equations:

1. the compiled kernel, one parameter set, a 60 s quick situation (situation 11's drive
   motion repeated for 60 s, 8.131 kg, final parameters: slack and snatches every cycle);
2. the kernel, a batch of 256 parameter sets (stiffness, damping, friction ±25 %);
3. solve_ivp on the same right-hand side (sim/reference.py) at *matching accuracy*: the
   loosest tolerance whose NRMSE against a tight reference is no worse than the kernel's.

Run: ``make bench`` or ``.venv/bin/python benchmarks/bench_model.py [--seconds 60]``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from drivers.signals import SignalSpec, plan_motion
from sim import _baseline
from sim.config import default_config
from sim.model import Model
from sim.reference import solve_reference
from sim.situations import situation

RATE = 2000.0


def nrmse(a: np.ndarray, ref: np.ndarray) -> float:
    return float(np.linalg.norm(a - ref) / np.linalg.norm(ref - ref.mean()))


def best_of(fn, repeats: int) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="simulated duration, s")
    parser.add_argument("--batch", type=int, default=256, help="parameter sets in the batch")
    parser.add_argument(
        "--match-seconds",
        type=float,
        default=10.0,
        help="window used to match solve_ivp's accuracy to the kernel's, s",
    )
    args = parser.parse_args()

    stand = default_config()
    s11 = situation("11")
    cycles = max(1, round((args.seconds - 1.5) * s11.signal.frequency_hz))
    spec = SignalSpec(**{**s11.signal.__dict__, "cycles": cycles})
    _, x = plan_motion(spec, stand.drive).sample(RATE)
    params = stand.stand_params("final", s11.mass_kg)
    sim_s = (x.size - 1) / RATE
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}"
    )
    print(f"run: situation 11 motion, {sim_s:.1f} s simulated, {x.size} samples at 2 kHz")

    model = Model(params)
    model.run(x[:100], RATE)  # compile (cached after the first run)
    single = best_of(lambda: model.run(x, RATE), 5)
    direct = best_of(lambda: _baseline.simulate(x, RATE, params), 5)
    run = model.run(x, RATE)
    print(
        f"kernel, single: {single * 1e3:8.1f} ms  -> {sim_s / single:8.0f}x real time "
        f"(slack {run.slack.mean() * 100:.0f} % of the time)"
    )
    print(f"  same run on the private kernel entry (no front door): {direct * 1e3:8.1f} ms")

    rng = np.random.default_rng(1)
    variants = [
        {
            "stiffness_n_m": params.stiffness_n_m * rng.uniform(0.75, 1.25),
            "damping_n_s_m": params.damping_n_s_m * rng.uniform(0.75, 1.25),
            "friction_scale": rng.uniform(0.75, 1.25),
        }
        for _ in range(args.batch)
    ]
    model.run_batch(x[:100], RATE, variants[:2])
    batch = best_of(lambda: model.run_batch(x, RATE, variants), 2)
    rows = np.stack([_baseline.param_vector(params.with_(**v)) for v in variants])
    rel = x - x[0]
    direct_batch = best_of(lambda: _baseline.simulate_rows(rel, RATE, rows, params.friction), 2)
    print(
        f"kernel, batch of {args.batch}: {batch:8.2f} s  -> {args.batch * sim_s / batch:8.0f}x "
        f"real time ({batch / args.batch * 1e3:.1f} ms per set)"
    )
    print(f"  same batch on the private kernel entry (no front door): {direct_batch:8.2f} s")

    # Accuracy matching on a window (the tight reference is slow).
    n_match = int(args.match_seconds * RATE) + 1
    xm = x[:n_match]
    tight = solve_reference(xm, RATE, params, method="DOP853", rtol=1e-11, atol=1e-14)
    ours = model.run(xm, RATE)
    target = max(nrmse(ours.u_m, tight.u_m), nrmse(ours.force_n, tight.force_n))
    print(
        f"kernel accuracy on {args.match_seconds:g} s: NRMSE {target:.2e} "
        "(worse of u and F, against DOP853 at rtol 1e-11)"
    )
    chosen = None
    for method in ("DOP853", "RK45", "LSODA", "Radau"):
        for rtol in (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10):
            start = time.perf_counter()
            ref = solve_reference(xm, RATE, params, method=method, rtol=rtol, atol=rtol * 1e-3)
            wall = time.perf_counter() - start
            err = max(nrmse(ref.u_m, tight.u_m), nrmse(ref.force_n, tight.force_n))
            if err <= target:
                print(
                    f"  solve_ivp {method:6s} rtol {rtol:.0e}: NRMSE {err:.2e}, "
                    f"{args.match_seconds / wall:6.1f}x real time"
                )
                if chosen is None or wall < chosen[2]:
                    chosen = (method, rtol, wall)
                break
    assert chosen is not None, "no solve_ivp setting reached the kernel's accuracy"
    method, rtol, _ = chosen
    start = time.perf_counter()
    solve_reference(x, RATE, params, method=method, rtol=rtol, atol=rtol * 1e-3)
    ref_wall = time.perf_counter() - start
    print(
        f"solve_ivp {method} rtol {rtol:.0e} (fastest at matching accuracy), full run: "
        f"{ref_wall:8.2f} s -> {sim_s / ref_wall:8.1f}x real time"
    )
    print(
        f"speed-up of the kernel over solve_ivp: single {ref_wall / single:.0f}x, "
        f"batched per set {ref_wall / (batch / args.batch):.0f}x"
    )


if __name__ == "__main__":
    main()
