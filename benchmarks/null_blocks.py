"""Calibration: the decision's false alarms on `none` campaigns, at two block lengths.

Each `none` campaign (both truth stands, both weights, seeds 1..N) is diagnosed; the
first stage's candidate outputs are then judged as one family (``decide.judge``'s maxT)
with held-out blocks of 0.25 s (the decision's) and of 0.125 s. Prints per campaign
the smallest family p-value, whether any candidate would be accepted, and the lag-one
correlation of neighbouring blocks' gains; then the summary. Under "no effect" the
smallest family p should be at least uniform (median ≥ 0.5) and below α = 0.05 at most
5 % of the time.

Run: ``.venv/bin/python benchmarks/null_blocks.py [--seeds 6]`` (about 30 s a campaign on
2 cores).
"""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Sequence
from typing import Any

import numpy as np

from sim.checks.check import MASSES_KG, CaseSpec, make_campaign
from sim.config import default_config
from sim.identify import decide, heldout
from sim.identify.heldout import Outputs
from sim.identify.traces import Trace

BLOCKS_S = (0.25, 0.125)
#: The diagnosis's pipeline, whose judge (of the first stage's refits) is wrapped.
_diagnose: Any = importlib.import_module("sim.identify.pipeline")


def _judge_at(
    traces: Sequence[Trace],
    before: Sequence[Outputs],
    candidates: dict[str, Sequence[Outputs]],
    block_s: float,
) -> tuple[float, bool, float]:
    """(smallest family p, any accepted, median lag-one correlation of block gains)."""
    gains = []
    for outs in candidates.values():
        eb, ea = heldout.block_errors(traces, before, outs, block_s=block_s)
        gains.append(np.log(np.maximum(eb, 1e-300) / np.maximum(ea, 1e-300)))
    g = np.stack(gains)
    p = decide.family_p_values(g)
    x_before = heldout.heldout_excess(traces, before)
    accepted = any(
        decide.Evidence(x_before, heldout.heldout_excess(traces, outs), 1.0, 0, float(pp)).accepted(
            len(candidates)
        )
        for outs, pp in zip(candidates.values(), p, strict=True)
    )
    lag = [float(np.corrcoef(row[:-1], row[1:])[0, 1]) for row in g if np.std(row) > 0]
    return float(p.min()), accepted, float(np.nanmedian(lag)) if lag else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=6, help="seeds 1..N (default 6)")
    args = parser.parse_args()
    stand = default_config()
    captured: dict[str, Any] = {}
    judge = _diagnose.judge

    def capture(traces: Any, before: Any, candidates: Any, *rest: Any, **kw: Any) -> Any:
        captured.setdefault("first", (traces, before, candidates))
        return judge(traces, before, candidates, *rest, **kw)

    _diagnose.judge = capture  # the first stage's refits, as the decision sees them
    rows: dict[float, list[tuple[float, bool, float]]] = {b: [] for b in BLOCKS_S}
    for seed in range(1, args.seeds + 1):
        for mass in MASSES_KG:
            for truth_stand in ("same", "other"):
                spec = CaseSpec("none", mass, 0, seed)
                traces, _, _ = make_campaign(
                    stand, "none", mass, spec.rng(), truth_stand=truth_stand
                )
                captured.clear()
                _diagnose.diagnose(traces, stand.stand_params("final", mass))
                traces_seen, before, candidates = captured["first"]
                line = f"seed {seed} {mass:g} kg {truth_stand:5s}"
                for block in BLOCKS_S:
                    result = _judge_at(traces_seen, before, candidates, block)
                    rows[block].append(result)
                    line += f" | {block:g} s: p_min {result[0]:.3f} {'FA' if result[1] else '  '}"
                print(line, flush=True)
    for block, found in rows.items():
        p_min = np.array([r[0] for r in found])
        print(
            f"{block:g} s blocks: {sum(r[1] for r in found)}/{len(found)} false alarms; "
            f"smallest family p median {np.median(p_min):.2f}, below 0.05 {np.sum(p_min < 0.05)}; "
            f"lag-one correlation median {np.nanmedian([r[2] for r in found]):.2f}"
        )


if __name__ == "__main__":
    main()
