"""What a restart costs a measurement effect: the true model, restarted, against one run.

    .venv/bin/python benchmarks/restart_error.py

Multiple shooting restarts every segment from the recorded channels
(``sim.identify.shooting``). For a gauge effect the restart must undo what the gauge did
(a skew read back in time, a low-pass's state). This simulates a clean light-weight
quick recording of the true model with each gauge effect, judges that same true model
restarted and in one open-loop run, and prints both held-out errors and their ratio:
1 means the restarts cost nothing. docs/effects.md quotes the table.
"""

from __future__ import annotations

import numpy as np

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.config import default_config
from sim.effects import EffectSpec
from sim.identify.fitting import Candidate, simulate_values
from sim.identify.heldout import Outputs, heldout_error
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


def main() -> None:
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
