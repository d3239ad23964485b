"""Check: every motion the prediction admits stays safe on the other truth stand.

The planner searches ``sim.planner.motion_grid``; ``labstand run`` admits a motion when
its prediction (the nominal model over ``NOMINAL_SPREAD``) keeps within the limits. Here
every grid motion the prediction admits, for both weights, is simulated on the
independently written stand (``sim.checks.otherstand``: its own integrator and effect forms,
not the model that predicted) at three true stands drawn as ``diagnose-check`` draws
them (k ×0.8–1.25, c ×0.7–1.4, friction ×0.8–1.25), each with one of the other stand's
physical effects drawn at random (or none), and checked against the limits: the slack
e-stop (recorded F < 2 N for > 0.25 s), the weight's travel and the fibre's safe peak
tension. The planner's set (``sim.planner.plannable``: ``PLAN_MARGIN`` inside every
limit) is checked as the planner runs it: each motion lengthened to a planned test
(``sim.motions.lengthened``) where that is plannable too, at three more true stands.
Prints the counts and every violation, and which of them were planned tests.

Run: ``.venv/bin/python benchmarks/plan_safety.py [--draws N]``.
"""

from __future__ import annotations

import argparse

import numpy as np

from drivers.signals import plan_motion
from sim.checks.otherstand import OTHER_EFFECTS, simulate
from sim.checks.otherstand.campaign import draw_true_stand
from sim.config import default_config
from sim.envelope import NOMINAL_SPREAD, Prediction, SlackRule, figures_of
from sim.motions import Candidate, lengthened
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
    counts = {"admitted": 0, "planned": 0, "lengthened": 0, "runs": 0, "planned_broken": 0}
    violations: list[str] = []
    worst = {"slack_s": 0.0, "travel_mm": 0.0, "tension_n": 0.0}

    def prediction(c: Candidate) -> Prediction:
        x = plan_motion(c.spec, config.drive).sample(rate)[1]
        stand = config.stand_params("final", c.mass_kg)
        return predict(stand, (), x, rate, NOMINAL_SPREAD, RULE.slack_force_n)

    def on_the_other_stand(c: Candidate, seed: int, label: str) -> int:
        """Runs of c at drawn true stands; how many broke a limit."""
        x = plan_motion(c.spec, config.drive).sample(rate)[1]
        stand = config.stand_params("final", c.mass_kg)
        rng = np.random.default_rng(seed)
        broke = 0
        for draw in range(args.draws):
            truth = draw_true_stand(stand, rng)
            effects = {}
            if draw:  # the first draw without an effect
                name = physical[int(rng.integers(len(physical)))]
                effects = {name: OTHER_EFFECTS[name].draw(rng)}
            run = simulate(truth, effects, x, rate)
            counts["runs"] += 1
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
                broke += 1
                violations.append(
                    f"{label}{c.describe()}, {c.spec.cycles} cycles "
                    f"({', '.join(effects) or 'no effect'}): {', '.join(broken)} (slack "
                    f"{f.longest_slack_s:.2f} s, travel {f.weight_travel_m * 1e3:.0f} mm, peak "
                    f"{f.peak_tension_n:.0f} N)"
                )
        return broke

    for i, c in enumerate(grid):
        p = prediction(c)
        if p.breaches(config.envelope, RULE):
            continue
        counts["admitted"] += 1
        on_the_other_stand(c, i, "")
        if not plannable(p, config.envelope, RULE):
            continue
        counts["planned"] += 1
        # what the planner runs: the motion lengthened to a planned test, if admissible
        test = lengthened(c, config.drive)
        if plannable(prediction(test), config.envelope, RULE):
            counts["lengthened"] += 1
        else:
            test = c
        counts["planned_broken"] += on_the_other_stand(test, 10_000 + i, "planner's test, ")
    print(
        f"grid {len(grid)} motions; admitted by the prediction {counts['admitted']}, "
        f"{counts['planned']} of them in the planner's set ({counts['lengthened']} of those "
        f"run lengthened to a planned test); {counts['runs']} runs on the other stand"
    )
    print(
        f"worst on the other stand: slack {worst['slack_s']:.2f} s, travel "
        f"{worst['travel_mm']:.0f} mm, peak {worst['tension_n']:.0f} N"
    )
    print(f"violations: {len(violations)}, of them planned tests: {counts['planned_broken']}")
    for line in violations:
        print(f"  {line}")


if __name__ == "__main__":
    main()
