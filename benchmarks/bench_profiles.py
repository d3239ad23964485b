"""Benchmark: what carrying the intervals' ends along their profiles adds to the intervals.

    .venv/bin/python benchmarks/bench_profiles.py [--rounds 3]

Per campaign (same-form check campaigns, the moderate recordings; the truth's candidate
at the truth's values, the fit a diagnosis would polish from): the final model's
intervals (``parameter_intervals`` with the bootstrap, as a diagnosis asks for them)
with ``along_profiles`` and without it, in turns; printed: the median of each.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: (effect, weight kg, check seed): a heavy branch, a light pulley, light string modes.
CAMPAIGNS = (("fibre_viscoelastic", 8.131, 6), ("pulley_inertia_friction", 3.096, 6),
             ("fibre_transverse_vibration", 3.096, 8))  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    import sim.identify.intervals as intervals
    from sim.checks.check import CaseSpec, make_campaign, recording_set
    from sim.config import load_config
    from sim.identify.fitting import Candidate

    stand = load_config(None)
    chosen = recording_set("moderate", stand)
    along = intervals.along_profiles

    def unchanged(objective, candidate, z, free, ends):  # type: ignore[no-untyped-def]
        return ends, 0

    for effect, mass, seed in CAMPAIGNS:
        spec = CaseSpec(effect, mass, 0, seed)
        traces, _, truth = make_campaign(stand, effect, mass, spec.rng(), chosen)
        nominal = stand.stand_params("final", mass)
        candidate = Candidate.build(effect)
        # The truth's own values: the baseline's multipliers and the effect's parameters.
        values = {p.name: truth[p.name.split(".")[-1]] for p in candidate.params}
        times: dict[str, list[float]] = {"with": [], "without": []}
        for _ in range(args.rounds):
            for label, fn in (("with", along), ("without", unchanged)):
                intervals.along_profiles = fn
                started = time.perf_counter()
                intervals.parameter_intervals(
                    candidate, values, traces, nominal, replicates=intervals.BIAS_REPLICATES
                )
                times[label].append(time.perf_counter() - started)
        intervals.along_profiles = along
        w, wo = statistics.median(times["with"]), statistics.median(times["without"])
        print(f"{effect:28s} {mass:5.3f} kg seed {seed}: with {w:6.2f} s, without {wo:6.2f} s, "
              f"the profiles {w - wo:+.2f} s ({(w - wo) / w:.0%})", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
