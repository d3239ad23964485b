"""Check: every motion the prediction admits stays safe on the other truth stand.

The planner searches ``sim.planner.motion_grid``; ``labstand run`` admits a motion when
its prediction (the nominal model over ``NOMINAL_SPREAD``) keeps within the limits. Here
every grid motion the prediction admits, for both weights, is simulated on the
independently written stand (``sim.checks.otherstand``: its own integrator and effect forms,
not the model that predicted) at three true stands drawn as ``diagnose-check`` draws
them (k ×0.8–1.25, c ×0.7–1.4, friction ×0.8–1.25), each with one of the other stand's
physical effects drawn at random (or none), and checked against the limits: the slack
e-stop (recorded F < 2 N for > 0.25 s), the weight's travel and the fibre's safe peak
tension. Prints the counts and every violation, and which of them the planner could plan
(its set, ``sim.planner.plannable``: ``PLAN_MARGIN`` inside every limit).

Run: ``.venv/bin/python benchmarks/plan_safety.py [--draws N]``.
"""

from __future__ import annotations

import argparse

import numpy as np

from drivers.signals import plan_motion
from sim.checks.otherstand import OTHER_EFFECTS, simulate
from sim.checks.otherstand.campaign import draw_true_stand
from sim.config import default_config
from sim.envelope import NOMINAL_SPREAD, SlackRule, figures_of
from sim.planner import motion_grid, plannable
from sim.prediction import predict

RULE = SlackRule(2.0, 0.25)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=3, help="true stands per motion (3)")
    args = parser.parse_args()
    config = default_config()
    rate = config.sample_rate_hz
    physical = [n for n, e in OTHER_EFFECTS.items() if e.kind == "physical"]
    grid = motion_grid(config.drive, sorted(config.weights_kg.values()))
    admitted = planned = runs = planned_broken = 0
    violations: list[str] = []
    worst = {"slack_s": 0.0, "travel_mm": 0.0, "tension_n": 0.0}
    for i, c in enumerate(grid):
        x = plan_motion(c.spec, config.drive).sample(rate)[1]
        stand = config.stand_params("final", c.mass_kg)
        p = predict(stand, (), x, rate, NOMINAL_SPREAD, RULE.slack_force_n)
        if p.breaches(config.envelope, RULE):
            continue
        admitted += 1
        in_set = plannable(p, config.envelope, RULE)
        planned += in_set
        rng = np.random.default_rng(i)
        for draw in range(args.draws):
            truth = draw_true_stand(stand, rng)
            effects = {}
            if draw:  # the first draw without an effect
                name = physical[int(rng.integers(len(physical)))]
                effects = {name: OTHER_EFFECTS[name].draw(rng)}
            run = simulate(truth, effects, x, rate)
            runs += 1
            f = figures_of(run.true_force_n, run.force_n, run.true_u_m, rate, RULE.slack_force_n)
            worst["slack_s"] = max(worst["slack_s"], f.longest_slack_s)
            worst["travel_mm"] = max(worst["travel_mm"], f.weight_travel_m * 1e3)
            worst["tension_n"] = max(worst["tension_n"], f.peak_tension_n)
            broken = [
                what
                for what, bad in (
                    ("slack", f.longest_slack_s > RULE.slack_max_s),
                    ("travel", f.weight_travel_m > config.envelope.weight_travel_max_m),
                    ("tension", f.peak_tension_n > config.envelope.fibre_tension_max_n),
                )
                if bad
            ]
            if broken:
                planned_broken += in_set
                violations.append(
                    ("planner's set, " if in_set else "")
                    + f"{c.describe()} ({', '.join(effects) or 'no effect'}): {', '.join(broken)}"
                    f" (slack {f.longest_slack_s:.2f} s, travel {f.weight_travel_m * 1e3:.0f}"
                    f" mm, peak {f.peak_tension_n:.0f} N)"
                )
    print(
        f"grid {len(grid)} motions; admitted by the prediction {admitted}, {planned} of them "
        f"in the planner's set; {runs} runs on the other stand"
    )
    print(
        f"worst on the other stand: slack {worst['slack_s']:.2f} s, travel "
        f"{worst['travel_mm']:.0f} mm, peak {worst['tension_n']:.0f} N"
    )
    print(f"violations: {len(violations)}, of them among the planner's: {planned_broken}")
    for line in violations:
        print(f"  {line}")


if __name__ == "__main__":
    main()
