"""``labstand cat``: a recording's samples (or events) in a time window, as text on stdout."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from labstand.errors import CommandError, ExitCode
from labstand.terminal import printable

#: channel name -> column (the same names as the CSV export and the CSV importer)
CHANNELS = {
    "x": "x_mm",
    "u": "u_mm",
    "F": "F_N",
    "x_cmd": "x_cmd_mm",
    "seq": "seq",
    "flags": "flags",
}
DEFAULT = ("x", "u", "F", "x_cmd", "seq", "flags")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand cat``."""
    parser = sub.add_parser(
        "cat",
        help="print samples or events of a time window as CSV text",
        description="Print the gauge samples of REC between --start and --end (s since the "
        "start of the run, both included) as CSV on stdout: t_s first, then the channels "
        "(x_mm, u_mm, F_N, x_cmd_mm when there is a command, seq, flags). With --events, "
        "the events instead, one per line: t_s, kind and text separated by tabs. MCAP and "
        "HDF5 files are read only around the window.",
    )
    add_window_options(parser)
    parser.add_argument(
        "--channels",
        metavar="x,u,F",
        help=f"channels to print, comma separated: {', '.join(CHANNELS)} (default: all)",
    )
    parser.add_argument("--events", action="store_true", help="print the events instead")
    parser.set_defaults(func=run)


def add_window_options(parser: argparse.ArgumentParser) -> None:
    """REC, --start T and --end T."""
    parser.add_argument("recording", type=Path, metavar="REC", help="recording (any format)")
    parser.add_argument("--start", type=float, metavar="T", help="from T s (default: the start)")
    parser.add_argument("--end", type=float, metavar="T", help="to T s (default: the end)")


def columns_for(spec: str | None, has_command: bool) -> list[str]:
    """The output columns for ``--channels`` (unknown names: exit 2)."""
    if spec is None:
        names = [n for n in DEFAULT if has_command or n != "x_cmd"]
    else:
        names = [n.strip() for n in spec.split(",") if n.strip()]
        by_column = {column: name for name, column in CHANNELS.items()}
        names = [by_column.get(n, n) for n in names]  # x_mm is accepted for x
        unknown = [n for n in names if n not in CHANNELS]
        if unknown or not names:
            raise CommandError(
                f"--channels {spec!r}: unknown channel(s) {', '.join(unknown) or '(none given)'}; "
                f"known: {', '.join(CHANNELS)}",
                ExitCode.USAGE,
            )
    return [CHANNELS[n] for n in names]


def run(args: argparse.Namespace) -> int:
    """Read the window, print it."""
    from recordings.window import read_window

    window = read_window(args.recording, args.start, args.end)
    rec = window.recording
    if args.events:
        for t_ns, kind, text in rec.events_array.tolist():
            flat = printable(" ".join(str(text).split()))  # no terminal escapes from a file
            sys.stdout.write(f"{t_ns / 1e9:.6f}\t{printable(str(kind))}\t{flat}\n")
        return 0
    columns = columns_for(args.channels, len(rec.command) > 0)
    if "x_cmd_mm" in columns and not len(rec.command):
        raise CommandError(f"{args.recording}: has no command stream (x_cmd)", ExitCode.USAGE)
    frame = rec.frame().reset_index()
    # floats by repr: the shortest text that reads back to the same number
    frame[["t_s", *columns]].to_csv(sys.stdout, index=False, lineterminator="\n")
    return 0
