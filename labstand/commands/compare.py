"""``labstand compare``: two recordings against each other, with the paper's measures."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


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
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Compare and report."""
    from recordings import open_recording

    a, b = open_recording(args.a), open_recording(args.b)  # refused before numba loads

    from labstand.commands.replay import print_metrics
    from labstand.plots import plot_replay
    from recordings.replay import compare_runs

    result = compare_runs(a.frame(), b.frame())
    out = {"a": str(args.a), "b": str(args.b), **result.to_dict()}
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
    print_metrics(result.metrics)
    for note in result.notes:
        print(f"  note: {note}")
    return 0
