"""``labstand table1``: the paper's Table 1 for a set of recordings (in parallel on Dask)."""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from labstand.distributed import add_cluster_options, run_many

LABEL = "labstand table1"


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand table1``."""
    parser = sub.add_parser(
        "table1",
        description="For each recording, R of the weight displacement and of the dynamic "
        "force for two parameter sets side by side (the paper's Table 1), plus NRMSE. "
        "Several recordings are replayed in parallel on Dask.",
    )
    parser.add_argument("recordings", type=Path, nargs="+", help="recordings")
    parser.add_argument("--first", default="starting", help="first parameter set (starting)")
    parser.add_argument("--second", default="final", help="second parameter set (final)")
    parser.add_argument("--stand", type=Path, metavar="FILE", help="stand file")
    parser.add_argument(
        "--mass-kg",
        type=float,
        help="weight mass, kg (default: the --stand file's default weight, else each "
        "recording's stored weight)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON rows (default: Markdown)")
    add_cluster_options(parser)
    parser.set_defaults(func=run)


@dataclass(frozen=True)
class Table1Job:
    """One recording's row, with both parameter sets."""

    recording: Path
    first: str
    second: str
    stand: Path | None
    mass_kg: float | None = None


def table1_row(job: Table1Job) -> dict[str, Any]:
    """The job: replay one recording with both sets (runs on a worker)."""
    from labstand.recording_stand import mass_source, params_for
    from recordings import open_recording
    from recordings.replay import replay

    recording = open_recording(job.recording)
    row: dict[str, Any] = {"recording": str(job.recording)}
    signal = recording.metadata.signal or {}
    row["signal"] = signal.get("shape", "")
    row["frequency_hz"] = signal.get("frequency_hz")
    row["mass_source"] = mass_source(recording, job.stand, job.mass_kg)
    for label, name in (("first", job.first), ("second", job.second)):
        params, _ = params_for(recording, job.stand, name, job.mass_kg)
        row["mass_kg"] = params.mass_kg
        metrics = replay(recording.frame(), params).metrics
        row[label] = {
            "params": name,
            "R_u": metrics["u"].R,
            "R_F_dyn": metrics["F_dyn"].R,
            "nrmse_u": metrics["u"].nrmse,
            "nrmse_F": metrics["F"].nrmse,
        }
    return row


def run(args: argparse.Namespace) -> int:
    """Replay every recording with both sets and tabulate."""
    jobs = [
        Table1Job(p, args.first, args.second, args.stand, args.mass_kg) for p in args.recordings
    ]
    rows, code = run_many(args, table1_row, jobs, [str(p) for p in args.recordings], LABEL)
    if not rows:
        return code
    if args.json:
        print(json.dumps(rows, indent=2))
        return code
    head = (
        f"| recording | signal | f [Hz] | m [kg] | R(u) {args.first} | R(u) {args.second} | "
        f"R(F) {args.first} | R(F) {args.second} | NRMSE(u) {args.second} | "
        f"NRMSE(F) {args.second} |"
    )
    print(head)
    print("|---" * (head.count("|") - 1) + "|")
    for r in rows:
        f, s = r["first"], r["second"]
        freq = "" if r["frequency_hz"] is None else f"{r['frequency_hz']:g}"
        print(
            f"| {Path(r['recording']).name} | {r['signal']} | {freq} | {r['mass_kg']:g} | "
            f"{f['R_u']:.6f} | "
            f"{s['R_u']:.6f} | {f['R_F_dyn']:.6f} | {s['R_F_dyn']:.6f} | {s['nrmse_u']:.4f} | "
            f"{s['nrmse_F']:.4f} |"
        )
    sources = sorted({r["mass_source"] for r in rows})
    print(f"\nMass: {'; '.join(sources)}.")
    return code
