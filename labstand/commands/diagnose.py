"""``labstand diagnose``: why the model disagrees with a set of recordings."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from labstand.distributed import add_cluster_options
from labstand.errors import CommandError, ExitCode
from labstand.targets import FOLDER

if TYPE_CHECKING:  # imported where they run: `diagnose --help` loads no numba or pandas
    from sim.config import StandConfig
    from sim.identify import Diagnosis

__all__ = ["register", "run"]


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand diagnose``."""
    parser = sub.add_parser(
        "diagnose",
        description="Fit the baseline (stiffness, damping, friction scale) to one or more "
        "recordings of one stand, say where the remaining gap lies, which of the nine "
        "candidate effects explains it (judged on held-out cycles), and how far it shrinks.",
    )
    parser.add_argument(
        "recordings", type=Path, nargs="*", help="recordings (.mcap .h5 .csv .tdms)"
    )
    parser.add_argument(
        "--campaigns",
        type=Path,
        metavar="FILE",
        help="diagnose every campaign of a TOML manifest ([campaign.NAME] tables with "
        "recordings, optional mass_kg (default: each recording's stored weight), stand and "
        "truth), in parallel on Dask",
    )
    parser.add_argument(
        "--results",
        type=Path,
        metavar="DIR",
        help="with --campaigns: write the results table and the confusion matrix here",
    )
    add_cluster_options(parser)
    parser.add_argument(
        "--stand",
        type=Path,
        metavar="FILE",
        help="nominal stand (default: the paper's, 'final' parameters)",
    )
    parser.add_argument("--params", default="final", help="nominal parameter set (final)")
    parser.add_argument(
        "--mass-kg",
        type=float,
        help="weight mass, kg (default: the --stand file's default weight, else each "
        "recording's stored weight)",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    parser.add_argument("--report", type=Path, metavar="DIR", help="write an HTML report here")
    parser.set_defaults(func=run, outputs={"report": FOLDER, "results": FOLDER})


def _mass_of(
    path: Path, stored: object, override: float | None, stand: StandConfig | None
) -> tuple[float, str]:
    """The weight mass for one recording and where it comes from (as ``params_for``)."""
    if override is not None:
        return override, "--mass-kg"
    if stand is not None:
        return stand.default_mass_kg, f"default weight of {stand.source}"
    from labstand.campaigns import stored_mass

    return stored_mass(path, stored)


def run(args: argparse.Namespace) -> int:
    """Read, diagnose, report (or, with --campaigns, every campaign of a manifest)."""
    from labstand.campaigns import trace_of, unique_names
    from labstand.commands.diagnose_many import run_campaigns
    from labstand.diagnosis_report import report_json, write_report
    from labstand.provenance import RecordingSource, build_provenance
    from recordings import RecordingError, open_recording
    from sim.config import load_config
    from sim.identify import DiagnosisInputError, diagnose

    if args.campaigns is not None:
        if args.recordings or args.report is not None or args.mass_kg is not None:
            raise CommandError(
                "--campaigns takes the recordings, masses and stands from its manifest "
                "(no recordings, --mass-kg or --report beside it)",
                ExitCode.USAGE,
            )
        return run_campaigns(args)
    if not args.recordings:
        raise CommandError("no recordings given (or --campaigns FILE)", ExitCode.USAGE)
    if args.results is not None:
        raise CommandError("--results goes with --campaigns", ExitCode.USAGE)
    config = load_config(args.stand)
    nominal = config.stand_params(args.params)
    if args.mass_kg is not None and not args.mass_kg > 0:
        raise CommandError(f"mass must be > 0 kg, got {args.mass_kg:g} kg", ExitCode.USAGE)
    traces = []
    masses: dict[str, dict[str, float | str]] = {}
    sources = []  # per recording, even one given twice: (path, kg, source, metadata)
    for path in args.recordings:
        try:
            rec = open_recording(path)
            stand = config if args.stand is not None else None
            mass, source = _mass_of(path, rec.metadata.stand_config, args.mass_kg, stand)
            masses[str(path)] = {"kg": mass, "source": source}
            traces.append(trace_of(path.name, rec.frame(), mass))
            sources.append((path, mass, source, rec.metadata.to_dict()))
        except (RecordingError, DiagnosisInputError) as err:
            raise CommandError(str(err), ExitCode.USAGE) from None
    traces = unique_names(traces)
    # Hashed before the diagnosis: the files as read, not as they may be later.
    provenance = build_provenance(
        [
            RecordingSource(path, tr.name, kg, source, meta)
            for (path, kg, source, meta), tr in zip(sources, traces, strict=True)
        ],
        args.stand,
        args.params,
    )

    def progress(message: str) -> None:
        print(f"labstand diagnose: {message}", file=sys.stderr, flush=True)

    result = diagnose(traces, nominal, progress=progress)
    index = (
        write_report(args.report, traces, result, provenance) if args.report is not None else None
    )
    if args.json:
        out = report_json(result, provenance)
        out["recordings"] = [str(p) for p in args.recordings]
        out["mass_kg"] = masses
        if index is not None:
            out["report"] = str(index)
        print(json.dumps(out, indent=2))
        return 0
    _print_summary(result, index)
    for path, m in masses.items():
        print(f"Mass: {Path(path).name} {m['kg']:g} kg ({m['source']})")
    return 0


def _with_interval(name: str, value: float, interval: tuple[float, float] | None) -> str:
    """``name = value [low, high]`` (the 95 % interval where there is one)."""
    shown = f"{name} = {value:.4g}"
    return f"{shown} [{interval[0]:.4g}, {interval[1]:.4g}]" if interval else shown


def _print_summary(result: Diagnosis, report: Path | None) -> None:
    from sim.identify.remainder import VERDICT_WORDS

    print(f"Verdict: {VERDICT_WORDS.get(result.verdict, result.verdict)}")
    print(f"Effect: {result.effect}")
    for e in result.effects:
        notes = []
        if e.at_bound:
            notes.append(
                f"{', '.join(e.at_bound)} at its bound: the effect may be larger or of another form"
            )
        if e.indistinguishable_from:
            notes.append(
                f"the recordings cannot tell it from {', '.join(e.indistinguishable_from)}"
            )
        params = ", ".join(_with_interval(k, v, e.intervals.get(k)) for k, v in e.params.items())
        print(f"  {e.effect}: closes {e.closure:.0%} of the gap (p = {e.p_value:.2g}); {params}")
        if e.reaches_bound:
            notes.append(f"{', '.join(e.reaches_bound)}: the interval reaches the range's end")
        for note in notes:
            print(f"    {note}")
    for effect, kind in result.displaced.items():
        print(f"  {effect}: passed its test but did no better than a {kind} term (not named)")
    rem = result.remainder
    if rem is not None:
        state = rem.state
        print(
            f"Remainder: {state} (p = {rem.p_value:.2g}); held-out error {rem.excess:.2f} × "
            f"noise, {rem.share_of_gap:.0%} of the baseline's gap"
        )
        for sig in [s for s in rem.signature if s.passes][:3]:
            print(f"  {sig.kind} in {sig.channel}: closes {sig.closes:.0%}; {sig.formula}")
    base = ", ".join(
        _with_interval(k, v, result.baseline_intervals.get(k)) for k, v in result.baseline.items()
    )
    print(f"Baseline (final model): {base}")
    closure = result.gap_closure_interval
    if closure is not None:
        low, high = closure
        print(f"Gap closed: {result.gap_closure:.0%} (95 % interval {low:.0%} to {high:.0%})")
    alone = result.baseline_consistency if result.effects else {}
    tests = [(t, " (baseline alone)") for t in alone.values()]
    for test, which in [*tests, *((t, "") for t in result.consistency.values())]:
        if test.get("trend"):
            pointer = f": {test['points_to']}" if test.get("points_to") else ""
            print(f"Per recording{which}: {test['trend']}{pointer}")
    for key, which in (("baseline_alone", " (baseline alone)" if result.effects else ""),
                       ("final", "")):  # fmt: skip
        rate = result.dynamic_stiffness.get(key)
        if rate:
            pointer = f": {rate['points_to']}" if rate.get("points_to") else ""
            print(f"Fibre law{which}: {rate['trend']}{pointer}")
    print("Held-out gap        before            after")
    for ch in ("u", "F"):
        b, a = result.gap_before[ch], result.gap_after[ch]
        print(
            f"  {ch}: NRMSE {b['nrmse']:.4f}  R {b['R']:.6f}"
            f"   NRMSE {a['nrmse']:.4f}  R {a['R']:.6f}"
        )
    print("Ranking (score = held-out gap closure; screening = share of residual explained):")
    for r in result.ranking[:5]:
        score = "   —  " if r.score is None else f"{r.score:6.3f}"
        bound = f"  ({', '.join(r.at_bound)} at its bound)" if r.at_bound else ""
        print(f"  {r.effect:28s} score {score}  screening {r.screening:.3f}{bound}")
    print("Where (share of the baseline's residual):")
    print("  channel: " + ", ".join(f"{k} {v:.0%}" for k, v in result.where.channel.items()))
    if report is not None:
        print(f"Report: {report}")
