"""What a restart costs a measurement effect: the true model, restarted, against one run.

    .venv/bin/python benchmarks/restart_error.py

Multiple shooting restarts every segment from the recorded channels
(``sim.identify.shooting``). For a gauge effect the restart must undo what the gauge did
(a skew read back in time, a low-pass's state). This simulates a clean light-weight
quick recording of the true model with each gauge effect, judges that same true model
restarted and in one open-loop run, and prints both held-out errors in units of the
error a real recording's gauge noise alone gives (0.5 µm, 0.02 N): the restarts cost
nothing that matters where the restarted error stands well below 1. docs/effects.md
quotes the table.

    .venv/bin/python benchmarks/restart_error.py --physical

    .venv/bin/python benchmarks/restart_error.py --noisy

judges the true model on the check's `none` campaigns (seeds 1–3, both weights, the
moderate recordings, the check's gauge and encoder noise) in units of each recording's
own noise floor: restarted with each start refined over its warm-up, restarted from the
local cubic fit alone, and in one open-loop run.

    .venv/bin/python benchmarks/restart_error.py --physical

does the same for the baseline and each physical effect at its defaults, both weights,
the four motions of ``labstand diagnose-check`` (``OTHER_FULL``): where a ratio stands
well above 1, a state the restart sets from the measurements is not the one the model
had (a ratio below 1 is chaos the restarts tame). Each cell is "restarted / one run" in
units of the held-out error the gauges' noise alone gives a real recording (0.5 µm,
0.02 N): a ratio is large wherever one run is nearly exact, and matters only where the
restarted error stands near or above 1.
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np

from drivers.limits import DriveLimits
from drivers.signals import Shape, SignalSpec, plan_motion
from sim.checks.otherstand.campaign import OTHER_FULL
from sim.config import default_config
from sim.effects import EFFECTS, EffectSpec
from sim.identify.fitting import Candidate, simulate_values
from sim.identify.heldout import Outputs, heldout_error, noise_floor
from sim.identify.traces import make_trace
from sim.model import Model

QUICK = SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=3, ramp_fraction=0.4)
MASS_KG = 3.096
BASE = {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0}
CASES = [
    ("force_gauge_dynamics", {"cutoff_hz": 20.0, "damping_ratio": 1.0}),
    ("force_gauge_dynamics", {"cutoff_hz": 12.0, "damping_ratio": 0.3}),
    ("force_gauge_dynamics", {"cutoff_hz": 30.0, "damping_ratio": 0.5}),
    ("force_gauge_dynamics", {"cutoff_hz": 40.0, "damping_ratio": 0.2}),
    ("force_gauge_dynamics", {"cutoff_hz": 60.0, "damping_ratio": 0.7}),
    ("channel_time_skew", {"force_skew_s": 0.0, "displacement_skew_s": 0.006}),
    ("channel_time_skew", {"force_skew_s": -0.004, "displacement_skew_s": 0.0}),
    ("channel_time_skew", {"force_skew_s": 0.0, "displacement_skew_s": -0.004}),
]


def _errors(
    effects: list[EffectSpec],
    signal: SignalSpec,
    mass_kg: float,
    noise: float = 0.0,
    limits: DriveLimits | None = None,
) -> tuple[float, float, float]:
    """Held-out errors of the true model restarted and in one run, on its own recording
    (gauge noise ``noise`` times 1 µm and 0.01 N), and the one a real recording's noise
    alone gives (0.5 µm, 0.02 N)."""
    stand = default_config()
    nominal = stand.stand_params("final", mass_kg)
    t, x = plan_motion(signal, limits or stand.drive).sample(stand.sample_rate_hz)
    run = Model(nominal, effects).run(x, stand.sample_rate_hz)
    rng = np.random.default_rng(0)  # a trace of noise: the rest level is never exactly 0
    u = run.u_m + noise * 1e-6 * rng.normal(size=x.size)
    f = run.force_n + noise * 1e-2 * rng.normal(size=x.size)
    trace = make_trace(signal.shape.value, t, x, u, f, mass_kg)
    values = dict(BASE)
    for spec in effects:
        values.update({f"{spec.name}.{k}": v for k, v in spec.resolved().items()})
    names = [spec.name for spec in effects]
    errors = []
    for shooting in (True, False):
        us, fs = simulate_values(
            Candidate.build(*names), [values], trace, nominal, shooting=shooting
        )
        errors.append(heldout_error([trace], [Outputs(us[0], fs[0])]))
    real = dataclasses.replace(trace, noise_u_m=5e-7, noise_force_n=0.02)
    return errors[0], errors[1], noise_floor([real])


def physical() -> None:
    """The baseline and each physical effect at its defaults: ratio per weight and motion."""
    names = [None, *(n for n, i in EFFECTS.items() if i.kind == "physical")]
    heads = [f"{rec.name} {kg:g} kg" for kg in (3.096, 8.131) for rec in OTHER_FULL]
    print(f"{'effect':28s} " + " ".join(f"{h:>16s}" for h in heads))
    for name in names:
        effects = [EffectSpec(name)] if name else []
        cells = []
        for kg in (3.096, 8.131):
            for rec in OTHER_FULL:
                restarted, one_run, floor = _errors(effects, rec.signal, kg, 0.01, rec.limits)
                cells.append(f"{restarted / floor:.2f} / {one_run / floor:.2f}".rjust(16))
        print(f"{name or 'baseline':28s} " + " ".join(cells), flush=True)


def noisy() -> None:
    """The true model on the check's ``none`` campaigns: refined, plain, one run."""
    from sim.checks.check import make_campaign, recording_set

    stand = default_config()
    heads = ("refined", "plain", "one run")
    print(f"{'kg':>6s} {'seed':>4s} {'recording':10s} " + " ".join(f"{h:>8s}" for h in heads))
    for mass in (3.096, 8.131):
        for seed in (1, 2, 3):
            rng = np.random.default_rng(seed)
            traces, _, truth = make_campaign(
                stand, "none", mass, rng, recording_set("moderate", stand), open_loop_oracle=True
            )
            nominal = stand.stand_params("final", mass)
            for trace in traces:
                plain = dataclasses.replace(trace)
                plain.__dict__["segments"] = dataclasses.replace(trace.segments, window=None)
                cells = []
                for tr, shooting in ((trace, True), (plain, True), (trace, False)):
                    u, f = simulate_values(Candidate.build(), [truth], tr, nominal, shooting)
                    cells.append(heldout_error([tr], [Outputs(u[0], f[0])]) / noise_floor([tr]))
                row = " ".join(f"{c:8.2f}" for c in cells)
                print(f"{mass:6.3f} {seed:4d} {trace.name:10s} {row}", flush=True)


def main() -> None:
    if "--physical" in sys.argv[1:]:
        physical()
        return
    if "--noisy" in sys.argv[1:]:
        noisy()
        return
    heads = ("restarted", "one run")
    print(f"{'effect':22s} {'parameters':56s} " + " ".join(f"{h:>10s}" for h in heads))
    for effect, params in CASES:
        restarted, one_run, floor = _errors([EffectSpec(effect, params)], QUICK, MASS_KG, 0.0, None)
        print(f"{effect:22s} {params!s:56s} {restarted / floor:10.3f} {one_run / floor:10.3f}")


if __name__ == "__main__":
    main()
