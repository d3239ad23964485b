"""Check: does the planned test settle an ambiguous diagnosis better than a random one?

Campaigns of a force channel that lags (``channel_time_skew`` at a drawn delay) recorded
by ``labstand simulate --noise`` on the validation's quick, medium and slow signals; each
whose diagnosis is ambiguous (a rival listed as indistinguishable) gets one more
recording twice, side by side: the motion ``labstand plan`` chooses, and a motion drawn
at random among those the safety prediction admits (fibre slack ≤ 5 % as the planner's).
Each is diagnosed again with the three starting recordings. Right: the truth is the named
effect; settled: and no rival is left beside it.

Run: ``.venv/bin/python benchmarks/plan_side_by_side.py [--campaigns N] [--dir DIR]``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from drivers.signals import SignalSpec, plan_motion
from labstand.commands.plan import diagnosed, noise_of, traces_of
from labstand.planning import plan_motion_for
from sim.config import default_config
from sim.envelope import NOMINAL_SPREAD, SlackRule
from sim.planner import PREDICTABLE_SLACK, motion_grid
from sim.prediction import predict

TRUTH = "channel_time_skew"
RULE = SlackRule(2.0, 0.25)
STARTING = {
    "quick": ["--signal", "trapezoidal", "--amplitude-mm", "25", "--frequency-hz", "2",
              "--cycles", "4", "--ramp-fraction", "0.4"],
    "medium": ["--signal", "trapezoidal", "--amplitude-mm", "25", "--frequency-hz", "1.25",
               "--cycles", "4", "--ramp-fraction", "0.4"],
    "slow": ["--signal", "quasi-sinusoidal", "--amplitude-mm", "60", "--frequency-hz", "0.5",
             "--cycles", "3"],
}  # fmt: skip


def simulate(out: Path, signal: list[str], effect: str, seed: int) -> Path:
    cmd = [sys.executable, "-m", "labstand", "simulate", *signal, "--effect", effect,
           "--noise", "--seed", str(seed), "-o", str(out)]  # fmt: skip
    subprocess.run(cmd, check=True, capture_output=True)
    return out


def signal_options(spec: SignalSpec, mass: float) -> list[str]:
    return [
        "--signal", str(spec.shape), "--amplitude-mm", f"{spec.amplitude_m * 1e3:g}",
        "--frequency-hz", f"{spec.frequency_hz:g}", "--cycles", str(spec.cycles),
        "--ramp-fraction", f"{spec.ramp_fraction:g}", "--mass-kg", f"{mass:g}",
    ]  # fmt: skip


def random_admissible(rng: np.random.Generator, mass: float) -> tuple[SignalSpec, float]:
    config = default_config()
    grid = motion_grid(config.drive, [mass])
    while True:
        c = grid[int(rng.integers(len(grid)))]
        x = plan_motion(c.spec, config.drive).sample(config.sample_rate_hz)[1]
        stand = config.stand_params("final", c.mass_kg)
        p = predict(stand, (), x, config.sample_rate_hz, NOMINAL_SPREAD, RULE.slack_force_n)
        if not p.breaches(config.envelope, RULE) and p.worst.slack_share <= PREDICTABLE_SLACK:
            return c.spec, c.mass_kg


def judge(paths: list[Path]) -> tuple[bool, bool, str]:
    fitted, _ = diagnosed(traces_of(paths, None), default_config(), "side-by-side")
    named = [e.name for e in fitted.effects]
    rivals = fitted.indistinguishable.get(named[0], []) if named else []
    right = bool(named) and named[0] == TRUTH
    return right, right and not rivals, f"{'+'.join(named) or 'none'} {rivals or ''}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaigns", type=int, default=6)
    parser.add_argument("--dir", type=Path, default=None)
    args = parser.parse_args()
    folder = args.dir or Path(tempfile.mkdtemp(prefix="plan-sbs-"))
    rng = np.random.default_rng(2026)
    config = default_config()
    counts = {"ambiguous": 0, "planned right": 0, "planned settled": 0, "random right": 0,
              "random settled": 0}  # fmt: skip
    for k in range(args.campaigns):
        skew = float(rng.uniform(0.5e-3, 2.0e-3))
        effect = f"{TRUTH}:force_skew_s={skew:.6f}"
        start = [simulate(folder / f"c{k}-{n}.h5", s, effect, 10 * k + i)
                 for i, (n, s) in enumerate(STARTING.items())]  # fmt: skip
        fitted, _ = diagnosed(traces_of(start, None), config, "side-by-side")
        named = [e.name for e in fitted.effects]
        rivals = fitted.indistinguishable.get(named[0], []) if named else []
        print(f"campaign {k}: skew {skew * 1e3:.2f} ms; first: {named} {rivals}", flush=True)
        if not rivals and named and named[0] == TRUTH:
            continue  # settled at once: nothing to plan
        counts["ambiguous"] += 1
        answer = plan_motion_for(fitted, config, [8.131], noise_of(traces_of(start, None)),
                                 RULE, 60.0)  # fmt: skip
        assert answer.plan.best is not None
        planned = simulate(folder / f"c{k}-planned.h5",
                           signal_options(answer.plan.best.spec, answer.plan.best.mass_kg),
                           effect, 10 * k + 5)  # fmt: skip
        spec, mass = random_admissible(rng, 8.131)
        drawn = simulate(folder / f"c{k}-random.h5", signal_options(spec, mass), effect,
                         10 * k + 6)  # fmt: skip
        for label, extra in (("planned", planned), ("random", drawn)):
            right, settled, words = judge([*start, extra])
            counts[f"{label} right"] += right
            counts[f"{label} settled"] += settled
            print(f"  {label}: {words}", flush=True)
        print(f"  plan: {answer.line()}", flush=True)
    print(counts)


if __name__ == "__main__":
    main()
