"""``labstand plot``: a quick look at a recording as a PNG."""

from __future__ import annotations

import argparse
from pathlib import Path

from labstand.commands.cat import add_window_options
from labstand.errors import CommandError, ExitCode
from labstand.targets import FILE, check_output

SUFFIXES = (".png", ".svg", ".pdf")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand plot``."""
    parser = sub.add_parser(
        "plot",
        description="Draw REC's drive position (with its command), weight displacement and "
        "fibre force over time, its events as lines and lost samples shaded, into a PNG "
        "(default: REC's name with .png, beside it). --start/--end draw a window (MCAP and "
        "HDF5 read only around it).",
    )
    add_window_options(parser)
    parser.add_argument("-o", "--output", type=Path, metavar="PNG", help="the PNG to write")
    parser.set_defaults(func=run, outputs={"output": FILE})


def run(args: argparse.Namespace) -> int:
    """Read (the window), draw, write."""
    from labstand.recording_plot import plot_recording
    from recordings.window import read_window

    out: Path = args.output or args.recording.with_suffix(".png")
    if out.suffix.lower() not in SUFFIXES:
        raise CommandError(
            f"{out}: cannot draw {out.suffix or 'files without a suffix'!r}; use one of "
            f"{', '.join(SUFFIXES)}",
            ExitCode.USAGE,
        )
    if args.output is None:  # the default name is checked here, as -o is by the CLI
        check_output(out, args.force)
    window = read_window(args.recording, args.start, args.end)
    rec = window.recording
    meta = rec.metadata
    what = [args.recording.name, meta.start_time_utc[:16].replace("T", " ")]
    what += [f"{meta.mass_kg:g} kg"] if meta.mass_kg is not None else []
    what += [v for v in (meta.operator, meta.sample) if v]
    plot_recording(out, rec, " · ".join(what))
    print(f"wrote {out} ({len(rec.gauges)} samples, t = {window.start_s:g} … {window.end_s:g} s)")
    return 0
