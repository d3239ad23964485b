"""``labstand table1``: the paper's Table 1 for a set of recordings."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand table1``."""
    parser = sub.add_parser(
        "table1",
        description="For each recording, R of the weight displacement and of the dynamic "
        "force for two parameter sets side by side (the paper's Table 1), plus NRMSE.",
    )
    parser.add_argument("recordings", type=Path, nargs="+", help="recordings")
    parser.add_argument("--first", default="starting", help="first parameter set (starting)")
    parser.add_argument("--second", default="final", help="second parameter set (final)")
    parser.add_argument("--stand", type=Path, metavar="FILE", help="stand file")
    parser.add_argument("--json", action="store_true", help="print JSON rows (default: Markdown)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Replay every recording with both sets and tabulate."""
    from labstand.recording_stand import params_for
    from recordings import open_recording
    from recordings.replay import replay

    rows: list[dict[str, Any]] = []
    for path in args.recordings:
        recording = open_recording(path)
        row: dict[str, Any] = {"recording": str(path)}
        signal = recording.metadata.signal or {}
        row["signal"] = signal.get("shape", "")
        row["frequency_hz"] = signal.get("frequency_hz")
        for label, name in (("first", args.first), ("second", args.second)):
            params, _ = params_for(recording, args.stand, name, None)
            metrics = replay(recording.frame(), params).metrics
            row[label] = {
                "params": name,
                "R_u": metrics["u"].R,
                "R_F_dyn": metrics["F_dyn"].R,
                "nrmse_u": metrics["u"].nrmse,
                "nrmse_F": metrics["F"].nrmse,
            }
        rows.append(row)
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    head = (
        f"| recording | signal | f [Hz] | R(u) {args.first} | R(u) {args.second} | "
        f"R(F) {args.first} | R(F) {args.second} | NRMSE(u) {args.second} | "
        f"NRMSE(F) {args.second} |"
    )
    print(head)
    print("|---" * (head.count("|") - 1) + "|")
    for r in rows:
        f, s = r["first"], r["second"]
        freq = "" if r["frequency_hz"] is None else f"{r['frequency_hz']:g}"
        print(
            f"| {Path(r['recording']).name} | {r['signal']} | {freq} | {f['R_u']:.6f} | "
            f"{s['R_u']:.6f} | {f['R_F_dyn']:.6f} | {s['R_F_dyn']:.6f} | {s['nrmse_u']:.4f} | "
            f"{s['nrmse_F']:.4f} |"
        )
    return 0
