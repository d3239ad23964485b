"""``labstand plan``: the next test, the admissible motion that best settles the diagnosis."""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.errors import CommandError, ExitCode
from labstand.targets import FILE

if TYPE_CHECKING:  # imported where they run: `plan --help` loads no numba
    from labstand.fitted import FittedStand
    from sim.config import StandConfig
    from sim.identify.traces import Trace
    from sim.planner import Noise

__all__ = ["diagnosed", "noise_of", "register", "run", "traces_of"]

#: The search's default time budget, s (the grid took 34 s on 2 heavily shared cores).
BUDGET_S = 40.0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand plan``."""
    parser = sub.add_parser(
        "plan",
        description="From the recordings' diagnosis (or a saved one, --diagnosis), search "
        "the motions the stand allows for the one whose outcome best separates the rival "
        "explanations, among those the safety prediction admits (docs/planning.md). "
        "`labstand run --plan PLAN.json` runs it.",
    )
    parser.add_argument(
        "recordings", type=Path, nargs="*", help="recordings of the stand (.mcap .h5 .csv)"
    )
    parser.add_argument(
        "--diagnosis",
        type=Path,
        metavar="RESULT.json",
        help="a saved `labstand diagnose --json` of these recordings (skips diagnosing them)",
    )
    parser.add_argument(
        "--stand", type=Path, metavar="FILE", help="the stand file (default: the paper's)"
    )
    parser.add_argument(
        "--mass-kg",
        type=float,
        help="plan for this weight only (default: every weight of the stand file)",
    )
    parser.add_argument(
        "--budget-s",
        type=float,
        default=BUDGET_S,
        help=f"time for the search, s (default {BUDGET_S:g}); the best motion so far then",
    )
    parser.add_argument("--json", action="store_true", help="print the plan as JSON")
    parser.add_argument(
        "-o", "--output", type=Path, help="write the plan as JSON here (for `run --plan`)"
    )
    parser.set_defaults(func=run, outputs={"output": FILE}, find_stand=True)


def _check(args: argparse.Namespace) -> None:
    if not args.recordings and args.diagnosis is None:
        raise CommandError("give recordings, or --diagnosis RESULT.json", ExitCode.USAGE)
    if not (math.isfinite(args.budget_s) and args.budget_s > 0):
        raise CommandError(f"--budget-s must be > 0 s, got {args.budget_s:g}", ExitCode.USAGE)
    if args.mass_kg is not None and not (math.isfinite(args.mass_kg) and args.mass_kg > 0):
        raise CommandError(f"--mass-kg: mass must be > 0 kg, got {args.mass_kg:g}", ExitCode.USAGE)


def traces_of(paths: list[Path], mass_kg: float | None) -> list[Trace]:
    """The recordings as diagnosis traces (each at ``mass_kg``, else its stored weight)."""
    from labstand.campaigns import stored_mass, trace_of, unique_names
    from recordings import RecordingError, open_recording
    from sim.identify import DiagnosisInputError

    traces = []
    for path in paths:
        try:
            rec = open_recording(path)
            mass = mass_kg
            if mass is None:
                mass, _ = stored_mass(path, rec.metadata.stand_config)
            traces.append(trace_of(path.name, rec.frame(), mass))
        except (RecordingError, DiagnosisInputError) as err:
            raise CommandError(str(err), ExitCode.USAGE) from None
    return unique_names(traces)


def diagnosed(
    traces: list[Trace], config: StandConfig, who: str
) -> tuple[FittedStand, dict[str, Any]]:
    """The recordings' diagnosis as the stand's model, and as JSON."""
    from labstand.fitted import fitted_from_dict
    from sim.identify import diagnose

    def progress(message: str) -> None:
        print(f"labstand {who}: {message}", file=sys.stderr, flush=True)

    result = diagnose(traces, config.stand_params("final"), progress=progress).to_dict()
    return fitted_from_dict(result, Path("(the recordings' diagnosis)")), result


def noise_of(traces: list[Trace]) -> Noise:
    """The recordings' gauge noise (median over them), else the simulated gauges'."""
    import numpy as np

    from sim.effects.realism import NoiseSpec
    from sim.planner import Noise

    if not traces:
        spec = NoiseSpec()
        return Noise(spec.displacement_rms_m, spec.force_rms_n)
    u = float(np.median([t.noise_u_m for t in traces]))
    f = float(np.median([t.noise_force_n for t in traces]))
    return Noise(max(u, 1e-7), max(f, 1e-3))  # at least one count of each gauge


def run(args: argparse.Namespace) -> int:
    """Diagnose (or read the diagnosis), search, say why, write the plan."""
    from labstand.planning import plan_motion_for
    from labstand.session.safety import SafetyLimits
    from sim.config import load_config
    from sim.envelope import SlackRule

    _check(args)
    config = load_config(args.stand)
    traces = traces_of(args.recordings, args.mass_kg)
    if args.diagnosis is not None:
        from labstand.fitted import read_diagnosis

        fitted = read_diagnosis(args.diagnosis)
    else:
        fitted, _ = diagnosed(traces, config, "plan")
    masses = [args.mass_kg] if args.mass_kg is not None else sorted(config.weights_kg.values())
    limits = SafetyLimits()
    rule = SlackRule(limits.slack_force_n, limits.slack_max_s)
    started = time.perf_counter()
    answer = plan_motion_for(fitted, config, masses, noise_of(traces), rule, args.budget_s, traces)
    out = answer.to_dict()
    out["search_s"] = time.perf_counter() - started
    if args.output is not None:  # under a temporary name, renamed when whole
        part = args.output.with_name(f".{args.output.name}.part")
        part.write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
        os.replace(part, args.output)
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print(answer.line())
        if args.output is not None:
            print(f"  wrote {args.output}: labstand run --plan {args.output} -o NEXT.mcap")
    return 0 if answer.plan.best is not None else ExitCode.REFUSED
