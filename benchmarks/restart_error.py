"""What a restart costs a measurement effect: the true model, restarted, against one run.

    .venv/bin/python benchmarks/restart_error.py

Multiple shooting restarts every segment from the recorded channels
(``sim.identify.shooting``). For a gauge effect the restart must undo what the gauge did
(a skew read back in time, a low-pass's state). This simulates a clean light-weight
quick recording of the true model with each gauge effect, judges that same true model
restarted and in one open-loop run, and prints both held-out errors and their ratio:
1 means the restarts cost nothing. docs/effects.md quotes the table.

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
    """Held-out errors of the true model restarted and in one run, on its own recording,
    and the one a real recording's noise alone gives (0.5 µm, 0.02 N)."""
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
        info = EFFECTS[spec.name]
        values.update({f"{spec.name}.{p.name}": p.default for p in info.params})
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


def main() -> None:
    if "--physical" in sys.argv[1:]:
        physical()
        return
    stand = default_config()
    nominal = stand.stand_params("final", MASS_KG)
    t, x = plan_motion(QUICK, stand.drive).sample(stand.sample_rate_hz)
    print(f"{'effect':22s} {'parameters':56s} {'restarted':>10s} {'one run':>10s} {'ratio':>6s}")
    for effect, params in CASES:
        run = Model(nominal, [EffectSpec(effect, params)]).run(x, stand.sample_rate_hz)
        trace = make_trace("quick", t, x, run.u_m, run.force_n, MASS_KG)
        values = dict(BASE, **{f"{effect}.{k}": v for k, v in params.items()})
        errors = []
        for shooting in (True, False):
            u, f = simulate_values(
                Candidate.build(effect), [values], trace, nominal, shooting=shooting
            )
            errors.append(heldout_error([trace], [Outputs(u[0], f[0])]))
        ratio = errors[0] / max(errors[1], np.finfo(float).tiny)
        print(f"{effect:22s} {params!s:56s} {errors[0]:10.5f} {errors[1]:10.5f} {ratio:6.1f}")


if __name__ == "__main__":
    main()
