"""Benchmark: ``labstand plan``'s search, batched, beside the same search one run at a time.

The rivals of the diagnosis of a campaign with a 1.1 ms force-channel skew (named:
force_gauge_dynamics, indistinguishable from channel_time_skew), the stand file's two
weights, the whole grid. Ours: ``sim.planner.search`` (each chunk of 24 motions is one
batch for the prediction's 9 corners and one per rival; on each admissible motion, per
pair and way round, one batch of segment runs of each rival from the other's noisy
recording: its values and a step of each refitted parameter, on all cores). Reference,
in the same run: the same judgements with one ``Model.run`` per motion and corner, per
rival, and one ``run_segments`` per rival and refit step, on the grid's first 24 motions,
scaled to the whole grid. Median of three
runs each (a first run compiles; it is not counted).

Run: ``.venv/bin/python benchmarks/bench_plan.py``.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from drivers.signals import plan_motion
from sim.config import default_config
from sim.discrimination import baseline_steps, effect_steps, recording_of
from sim.effects import EffectSpec
from sim.envelope import FITTED_SPREAD, Prediction, SlackRule, figures_of, worst_of
from sim.identify.shooting import Segments
from sim.identify.traces import Trace
from sim.model import Model
from sim.planner import CHUNK, Noise, Rival, Setting, motion_grid, plannable, search

GAUGE = EffectSpec("force_gauge_dynamics", {"cutoff_hz": 221.65, "damping_ratio": 0.715})
SKEW = EffectSpec("channel_time_skew", {"force_skew_s": 0.0011})
REFERENCE_SAMPLE = 24  # motions the one-at-a-time reference runs


def setting() -> Setting:
    config = default_config()
    return Setting(
        nominal=config.stand_params("final"),
        spread=FITTED_SPREAD,
        named=(GAUGE,),
        rivals=(Rival("gauge", (GAUGE,)), Rival("skew", (SKEW,))),
        pairs=(("gauge", "skew"),),
        noise=Noise(5e-6, 0.1),
        envelope=config.envelope,
        rule=SlackRule(2.0, 0.25),
        limits=config.drive,
        rate_hz=config.sample_rate_hz,
    )


def one_at_a_time(s: Setting, motions: list) -> None:  # type: ignore[type-arg]
    for c in motions:
        x = plan_motion(c.spec, s.limits).sample(s.rate_hz)[1]
        stand = s.nominal.with_(mass_kg=c.mass_kg)
        figures = []
        for k, d, f in s.spread.corners():
            variant = stand.with_(
                stiffness_n_m=stand.stiffness_n_m * k,
                damping_n_s_m=stand.damping_n_s_m * d,
                friction_scale=stand.friction_scale * f,
            )
            r = Model(variant, s.named).run(x, s.rate_hz)
            figures.append(figures_of(r.true_force_n, r.force_n, r.true_u_m, s.rate_hz, 2.0))
        worst = Prediction(figures[0], worst_of(figures), len(figures))
        if not plannable(worst, s.envelope, s.rule):
            continue
        runs = {r.name: Model(stand, r.effects).run(x, s.rate_hz) for r in s.rivals}
        models = {r.name: r.effects for r in s.rivals}
        noise = (s.noise.u_m, s.noise.force_n)
        for a, b in s.pairs:
            for truth, other in ((a, b), (b, a)):
                run = runs[truth]
                rec = recording_of(truth, x, run.u_m, run.force_n, s.rate_hz, c.mass_kg, noise)

                def scaled(model: Model, rec: Trace = rec, seg: Segments = rec.segments) -> Any:
                    u, f = model.run_segments(rec.x_m, s.rate_hz, seg.restarts)
                    return np.concatenate([seg.assemble(u)[0] / s.noise.u_m,
                                           seg.assemble(f)[0] / s.noise.force_n])  # fmt: skip

                target = scaled(Model(stand, models[truth]))
                model = Model(stand, models[other])
                steps = [{}, *baseline_steps(stand), *effect_steps(models[other])]
                z = [scaled(model.variant(step)) for step in steps]
                miss = target - z[0]
                directions = np.column_stack([v - z[0] for v in z[1:]])
                miss -= directions @ np.linalg.lstsq(directions, miss, rcond=None)[0]
                data = np.concatenate([rec.u_m / s.noise.u_m, rec.force_n / s.noise.force_n])
                held = np.concatenate([rec.test, rec.test])
                float(
                    np.sqrt(np.mean(miss[held] ** 2)) / np.sqrt(np.mean((data - target)[held] ** 2))
                )


def main() -> None:
    config = default_config()
    s = setting()
    grid = motion_grid(config.drive, sorted(config.weights_kg.values()))
    print(f"grid: {len(grid)} motions, {CHUNK} per batch")
    search(s, grid[:CHUNK], 600.0)  # compile
    times, plan = [], None
    for _ in range(3):
        started = time.perf_counter()
        plan = search(s, grid, 600.0)
        times.append(time.perf_counter() - started)
    assert plan is not None and plan.best is not None
    print(f"  ours: batched search           {np.median(times):6.1f} s  (median of 3)")
    print(f"    {plan.admissible} admissible; {plan.best.describe()}, "
          f"separation {plan.expected_separation:.1f} noise units")  # fmt: skip
    sample = grid[:REFERENCE_SAMPLE]
    one_at_a_time(s, sample[:1])
    ref = []
    for _ in range(3):
        started = time.perf_counter()
        one_at_a_time(s, sample)
        ref.append((time.perf_counter() - started) * len(grid) / len(sample))
    print(f"  reference: one run at a time  {np.median(ref):6.1f} s  (scaled from "
          f"{REFERENCE_SAMPLE} motions)")  # fmt: skip


if __name__ == "__main__":
    main()
