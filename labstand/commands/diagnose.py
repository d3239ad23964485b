"""``labstand diagnose``: why the model disagrees with a set of recordings."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from labstand.diagnosis_report import write_report
from labstand.errors import CommandError, ExitCode
from recordings import RecordingError, open_recording
from recordings.diagnosis import DiagnosisInputError, diagnose, make_trace
from sim.config import ConfigError, config_from_dict, load_config


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand diagnose``."""
    parser = sub.add_parser(
        "diagnose",
        help="find which unmodelled effect explains the gap between model and recordings",
        description="Fit the baseline (stiffness, damping, friction scale) to one or more "
        "recordings of one stand, say where the remaining gap lies, which of the nine "
        "candidate effects explains it (judged on held-out cycles), and how far it shrinks.",
    )
    parser.add_argument(
        "recordings", type=Path, nargs="+", help="recordings (.mcap .h5 .csv .tdms)"
    )
    parser.add_argument(
        "--stand",
        type=Path,
        metavar="FILE",
        help="nominal stand (default: the paper's, 'final' parameters)",
    )
    parser.add_argument("--params", default="final", help="nominal parameter set (final)")
    parser.add_argument(
        "--mass-kg", type=float, help="weight mass, kg (default: each recording's stored weight)"
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    parser.add_argument("--report", type=Path, metavar="DIR", help="write an HTML report here")
    parser.set_defaults(func=run)


def _mass_of(path: Path, stored: object, override: float | None, fallback: float) -> float:
    if override is not None:
        return override
    try:
        return config_from_dict(stored, str(path)).default_mass_kg  # type: ignore[arg-type]
    except (ConfigError, TypeError):
        return fallback


def run(args: argparse.Namespace) -> int:
    """Read, diagnose, report."""
    config = load_config(args.stand)
    nominal = config.stand_params(args.params)
    if args.mass_kg is not None and not args.mass_kg > 0:
        raise CommandError(f"mass must be > 0 kg, got {args.mass_kg:g} kg", ExitCode.USAGE)
    traces = []
    for path in args.recordings:
        try:
            rec = open_recording(path)
            mass = _mass_of(path, rec.metadata.stand_config, args.mass_kg, config.default_mass_kg)
            traces.append(make_trace(path.name, rec.frame(), mass))
        except (RecordingError, DiagnosisInputError) as err:
            raise CommandError(str(err), ExitCode.USAGE) from None
    names = [t.name for t in traces]
    if len(set(names)) != len(names):
        traces = [
            t.__class__(**{**t.__dict__, "name": f"{i}:{t.name}"}) for i, t in enumerate(traces)
        ]

    def progress(message: str) -> None:
        print(f"labstand diagnose: {message}", file=sys.stderr, flush=True)

    result = diagnose(traces, nominal, progress=progress)
    out = result.to_dict()
    out["recordings"] = [str(p) for p in args.recordings]
    if args.report is not None:
        index = write_report(args.report, traces, result)
        out["report"] = str(index)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    _print_summary(out)
    return 0


def _print_summary(out: dict[str, object]) -> None:
    effect = out["effect"]
    print(f"Effect: {effect}")
    before, after = out["gap_before"], out["gap_after"]
    print("Held-out gap        before            after")
    for ch in ("u", "F"):
        b, a = before[ch], after[ch]  # type: ignore[index]
        print(
            f"  {ch}: NRMSE {b['nrmse']:.4f}  R {b['R']:.5f}"
            f"   NRMSE {a['nrmse']:.4f}  R {a['R']:.5f}"
        )
    print("Ranking (score = held-out gap closure; screening = share of residual explained):")
    for r in out["ranking"][:5]:  # type: ignore[index]
        score = "   —  " if r["score"] is None else f"{r['score']:6.3f}"
        print(f"  {r['effect']:28s} score {score}  screening {r['screening']:.3f}")
    where = out["where"]
    print("Where (share of the baseline's residual):")
    print("  channel: " + ", ".join(f"{k} {v:.0%}" for k, v in where["channel"].items()))  # type: ignore[index]
    if "report" in out:
        print(f"Report: {out['report']}")
