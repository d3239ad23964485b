"""``labstand cat``: a recording's samples (or events) in a time window, as text on stdout."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from labstand.errors import CommandError, ExitCode
from labstand.terminal import printable

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

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
    frame = rec.frame().reset_index()[["t_s", *columns]]
    frame["t_s"] = [seconds_text(t) for t in rec.gauges["t_ns"].tolist()]
    for name in columns:
        if frame[name].dtype.kind == "f":
            frame[name] = number_text(frame[name].to_numpy())
    frame.to_csv(sys.stdout, index=False, lineterminator="\n")
    return 0


#: Most decimals a gauge's resolution has (counts of 1 µm, 1 mN: 3 or 4).
MAX_DECIMALS = 6


def number_text(values: NDArray[np.float64]) -> list[str]:
    """A column as text: at its resolution when its values sit on one, else exactly.

    Gauge values are counts times a step (21.8542 is 218542 × 0.0001, stored as
    21.854200000000002): printed to the step's decimals they read as measured. Values on
    no such step (the model's output) print as repr, the shortest text that reads back.
    """
    import numpy as np

    finite = values[np.isfinite(values)]
    for decimals in range(1, MAX_DECIMALS + 1):
        step = np.round(finite, decimals)
        if np.all(np.abs(step - finite) <= 4 * np.spacing(np.abs(finite))):
            text: list[str] = np.char.mod(f"%.{decimals}f", values).tolist()
            return [t if np.isfinite(v) else "" for t, v in zip(text, values.tolist(), strict=True)]
    return [repr(v) if math.isfinite(v) else "" for v in values.tolist()]


def seconds_text(t_ns: int) -> str:
    """Nanoseconds as exact decimal seconds (0.0, 0.0005, 12.000000001)."""
    sign, t_ns = ("-", -t_ns) if t_ns < 0 else ("", t_ns)
    whole, frac = divmod(t_ns, 1_000_000_000)
    return f"{sign}{whole}.{f'{frac:09d}'.rstrip('0') or '0'}"
