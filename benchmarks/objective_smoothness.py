"""Is a refit's objective smooth at the optimiser's difference step?

    .venv/bin/python benchmarks/objective_smoothness.py [--truth EFFECT] [--mass KG]
        [--seed N] [--point JSON]

The diagnosis' refits take forward differences of 1e-3 of each parameter's range
(``fitting.Objective.jacobian``); where the training cost is rough at that scale, the
gradient is noise and a refit stalls. This draws one check campaign (``--truth`` on the
other stand, seed and mass as ``diagnose-check``), and prints, for each parameter of the
truth's candidate at ``--point`` (its values, JSON; default: where the rim-block kernel's
light-pulley refit stalled, docs/diagnosis.md "Time"), the successive differences of the
training cost over ±5 difference steps. Smooth: differences that change slowly; rough:
differences that swing in sign.
"""

from __future__ import annotations

import argparse
import dataclasses
import json

import numpy as np

from sim.checks.check import CaseSpec, make_campaign
from sim.config import default_config
from sim.identify.fitting import Candidate, Objective
from sim.identify.shooting import dial_slope

STALLED = {
    "stiffness_scale": 1.21,
    "damping_scale": 0.782,
    "friction_scale": 1.37,
    "pulley_inertia_friction.inertia_kg_m2": 1.95e-05,
    "pulley_inertia_friction.bearing_torque_n_m": 0.00122,
    "pulley_inertia_friction.load_coeff": 0.00527,
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--truth", default="pulley_inertia_friction")
    ap.add_argument("--mass", type=float, default=3.096)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--point", type=json.loads, default=STALLED)
    a = ap.parse_args()
    stand = default_config()
    spec = CaseSpec(a.truth, a.mass, 0, a.seed)
    traces, _, _ = make_campaign(stand, a.truth, a.mass, spec.rng(), truth_stand="other")
    slope = dial_slope(traces)
    traces = [dataclasses.replace(tr, dial_slope=slope) for tr in traces]
    candidate = Candidate.build(a.truth)
    objective = Objective(candidate, traces, stand.stand_params("final", a.mass))
    z0 = np.array([p.to_internal(a.point[p.name]) for p in candidate.params])
    for i, p in enumerate(candidate.params):
        lo, hi = p.bounds()
        steps = np.arange(-5, 6)[:, None] * 1e-3 * (hi - lo) * np.eye(z0.size)[i]
        costs = np.sum(objective.residuals_batch(z0 + steps) ** 2, axis=1)
        print(f"{p.name:45s} differences ×1e6: {np.round(np.diff(costs) * 1e6, 1)}")


if __name__ == "__main__":
    main()
