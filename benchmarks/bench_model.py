"""Benchmark: real-time factor of the baseline model against scipy's solve_ivp.

Side by side in one run, on the same machine and the same equations:

1. the compiled kernel, one parameter set, a 60 s quick situation (situation 11's drive
   motion repeated for 60 s, 8.131 kg, final parameters: slack and snatches every cycle);
2. the kernel, a batch of 256 parameter sets (stiffness, damping, friction ±25 %);
3. solve_ivp on the same right-hand side (sim/reference.py) at *matching accuracy*: the
   loosest tolerance whose NRMSE against a tight reference is no worse than the kernel's;
4. the composed kernel: the kernel with one built-in physical effect (side_load_friction at
   μ_s = 0) against a kernel composed with an added effect (the tenth of
   tests/effects/weight_viscous_damping.py, registered here, at b = 0): the same
   arithmetic plus the added force's call.

Run: ``make bench`` or ``.venv/bin/python benchmarks/bench_model.py [--seconds 60]``.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the added effect is in tests/

from drivers.signals import SignalSpec, plan_motion
from sim.config import default_config
from sim.effects import EffectSpec, register, unregister
from sim.model import Model, Variant
from sim.params import StandParams
from sim.physics import runs
from sim.reference import solve_reference
from sim.situations import situation
from tests.effects import weight_viscous_damping

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


def best_in_turns(fns: Sequence[Callable[[], object]], repeats: int) -> list[float]:
    """Best time of each run, taken in turns (a, b, c, a, b, c, ...): load hits all alike."""
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, out in zip(fns, times, strict=True):
            start = time.perf_counter()
            fn()
            out.append(time.perf_counter() - start)
    return [min(t) for t in times]


def composed_kernel(x: np.ndarray, params: StandParams, variants: Sequence[Variant]) -> None:
    """A built-in physical effect against an added one (a composed kernel), both at zero."""
    print("composed kernel (compile excluded; runs taken in turns, best of each):")
    saved = os.environ.get("LABSTAND_KERNEL_CACHE")
    with tempfile.TemporaryDirectory(prefix="labstand-kernels-") as cache:
        os.environ["LABSTAND_KERNEL_CACHE"] = cache  # a fresh composed kernel, compiled here
        info = register(weight_viscous_damping.INFO)
        try:
            side = EffectSpec("side_load_friction", {"friction_coeff": 0.0})
            damping = EffectSpec(info.name, {"damping_n_s_m": 0.0})
            models = {
                "built-in side_load_friction (mu_s 0)": Model(params, [side]),
                f"composed, {info.name} (b 0)": Model(params, [damping]),
                "composed, both (the built-in's arithmetic + the call)": Model(
                    params, [side, damping]
                ),
            }
            builtin = next(iter(models.values()))
            builtin.run(x[:100], RATE)
            builtin.run_batch(x[:100], RATE, variants[:2])
            start = time.perf_counter()
            for model in list(models.values())[1:]:
                model.run(x[:100], RATE)
                model.run_batch(x[:100], RATE, variants[:2])
            compose_s = time.perf_counter() - start
            print(f"  composing and compiling the added effect's kernel (once): {compose_s:6.1f} s")
            singles = best_in_turns([partial(m.run, x, RATE) for m in models.values()], 5)
            batches = best_in_turns(
                [partial(m.run_batch, x, RATE, variants) for m in models.values()], 2
            )
            print(f"  {'':54s} {'one run':>10s} {f'batch of {len(variants)}':>12s}  / built-in")
            for name, one, many in zip(models, singles, batches, strict=True):
                print(
                    f"  {name:54s} {one * 1e3:7.1f} ms {many:10.2f} s  "
                    f"{one / singles[0]:.3f} {many / batches[0]:.3f}"
                )
            forces = [m.run(x, RATE).force_n for m in models.values()]
            diff = max(float(np.max(np.abs(f - forces[0]))) for f in forces[1:])
            print(f"  largest force difference from the built-in's run: {diff:.1e} N")
        finally:
            unregister(info.name)
            if saved is None:
                del os.environ["LABSTAND_KERNEL_CACHE"]
            else:
                os.environ["LABSTAND_KERNEL_CACHE"] = saved


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
    parser.add_argument(
        "--composed-batch",
        type=int,
        default=64,
        help="parameter sets in the composed kernel's batch",
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
    direct = best_of(lambda: runs.simulate(x, RATE, params), 5)
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
    rows = np.stack([runs.parameter_row(params.with_(**v)) for v in variants])
    rel = x - x[0]
    direct_batch = best_of(lambda: runs.simulate_rows(rel, RATE, rows, params.friction), 2)
    print(
        f"kernel, batch of {args.batch}: {batch:8.2f} s  -> {args.batch * sim_s / batch:8.0f}x "
        f"real time ({batch / args.batch * 1e3:.1f} ms per set)"
    )
    print(f"  same batch on the private kernel entry (no front door): {direct_batch:8.2f} s")
    composed_kernel(x, params, variants[: args.composed_batch])

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
