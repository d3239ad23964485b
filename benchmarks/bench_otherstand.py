"""Benchmark: the other truth stand's simulator per 10 s recording, beside the baseline model.

A 10 s recording at 2 kHz (a 30 mm, 1 Hz trapezoid that slackens the fibre, 9 cycles,
0.5 s rest each side) of the heavy weight: ``sim.checks.otherstand.simulate`` without effects,
with each physical effect, and with all of them at once; beside it, as the reference in
the same run, ``sim.model.Model(stand).run`` (the baseline kernel) and with a candidate
effect. Median of five runs each, compile time excluded.

Run: ``.venv/bin/python benchmarks/bench_otherstand.py``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.checks.otherstand import OTHER_EFFECTS, simulate
from sim.config import default_config
from sim.effects import EffectSpec
from sim.model import Model

RATE = 2000.0


def median_seconds(run: Callable[[], object], repeats: int = 5) -> float:
    run()  # compile / warm
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    return float(np.median(times))


def main() -> None:
    config = default_config()
    stand = config.stand_params("final", 8.131)
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.030, 1.0, cycles=9, ramp_fraction=0.2,
                      dwell_start_s=0.5, dwell_end_s=0.5)  # fmt: skip
    _, x = plan_motion(spec, config.drive).sample(RATE)
    print(f"one recording: {x.size / RATE:.1f} s at {RATE:g} Hz")
    rng = np.random.default_rng(0)
    physical = {n: e.draw(rng) for n, e in OTHER_EFFECTS.items() if e.kind == "physical"}
    rows = [("otherstand, no effect", lambda: simulate(stand, {}, x, RATE))]
    for name, params in physical.items():
        rows.append(
            (f"otherstand, {name}", lambda n=name, p=params: simulate(stand, {n: p}, x, RATE))
        )
    rows.append(("otherstand, all six physical", lambda: simulate(stand, physical, x, RATE)))
    rows.append(("reference: Model(stand).run", lambda: Model(stand).run(x, RATE)))
    ve = [EffectSpec("fibre_viscoelastic")]
    rows.append(
        ("reference: Model(stand, viscoelastic).run", lambda: Model(stand, ve).run(x, RATE))
    )
    for label, run in rows:
        print(f"  {label:45s} {median_seconds(run):6.3f} s")


if __name__ == "__main__":
    main()
