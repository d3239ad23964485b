"""``labstand compare``: two recordings against each other, with the paper's measures."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from labstand.targets import FILE

if TYPE_CHECKING:
    from recordings.schema import RecordingMetadata


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand compare``."""
    parser = sub.add_parser(
        "compare",
        description="Compare recording B against recording A (aligned on the start of the "
        "drive motion): R, psi and NRMSE of u, F and F − T0.",
    )
    parser.add_argument("a", type=Path, help="first recording (the reference)")
    parser.add_argument("b", type=Path, help="second recording")
    parser.add_argument("--json", action="store_true", help="print JSON (channels.u.R, ...)")
    parser.add_argument("--plot", type=Path, metavar="PNG", help="A vs B + difference")
    parser.set_defaults(func=run, outputs={"plot": FILE})


def run(args: argparse.Namespace) -> int:
    """Compare and report."""
    from recordings import open_recording

    a, b = open_recording(args.a), open_recording(args.b)  # refused before numba loads

    from labstand.commands.replay import print_metrics
    from labstand.plots import plot_replay
    from recordings.replay import compare_runs

    result = compare_runs(a.frame(), b.frame())
    warnings = differences(a.metadata, b.metadata)
    out = {"a": str(args.a), "b": str(args.b), **result.to_dict(), "warnings": warnings}
    if args.plot is not None:
        plot_replay(
            args.plot,
            result,
            f"{args.a.name} vs {args.b.name}",
            second_label=args.b.name,
            first_label=args.a.name,
        )
        out["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"{args.b} against {args.a}:")
    for warning in warnings:
        print(f"  warning: {warning}")
    print_metrics(result.metrics)
    for note in result.notes:
        print(f"  note: {note}")
    return 0


#: Signal keys that make two runs different motions (situation is only a name for them).
SIGNAL_KEYS = ("shape", "amplitude_mm", "frequency_hz", "cycles", "dwell_start_s", "dwell_end_s")


def differences(a: RecordingMetadata, b: RecordingMetadata) -> list[str]:
    """Why A and B are not two runs of one test: signal or mass (R would then mislead)."""
    out = []
    sa, sb = a.signal or {}, b.signal or {}
    changed = [
        f"{k} {sa.get(k, '?')} vs {sb.get(k, '?')}" for k in SIGNAL_KEYS if sa.get(k) != sb.get(k)
    ]
    if changed and (sa or sb):
        out.append(f"the drive signals differ ({', '.join(changed)}): not one test run twice")
    ma, mb = a.mass_kg, b.mass_kg
    if ma is not None and mb is not None and abs(ma - mb) > 1e-9 * max(ma, mb):
        out.append(f"the masses differ ({ma:g} kg vs {mb:g} kg): not one test run twice")
    return out
