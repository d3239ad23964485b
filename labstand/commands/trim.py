"""``labstand trim``: a time window of a recording as a new recording."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from labstand.commands.cat import add_window_options
from labstand.commands.convert import check_target
from labstand.errors import CommandError, ExitCode

if TYPE_CHECKING:
    from recordings.window import Window
from labstand.targets import FILE


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand trim``."""
    parser = sub.add_parser(
        "trim",
        help="cut a time window out of a recording into a new one",
        description="Write the part of REC between --start and --end (s since the start of "
        "the run, both included) to OUT, in the format of OUT's suffix (.mcap, .h5, .csv, "
        ".parquet). Every stream is cut to the window and keeps its times; the metadata is "
        "kept, with a note of what was cut; only the events inside the window are kept.",
    )
    add_window_options(parser)
    parser.add_argument("-o", "--output", type=Path, required=True, help="the new recording")
    parser.set_defaults(func=run, outputs={"output": FILE})


def run(args: argparse.Namespace) -> int:
    """Read the window, write it."""
    from recordings.convert import with_changes, write_recording

    if args.start is None and args.end is None:
        raise CommandError("give --start T and/or --end T (s)", ExitCode.USAGE)
    check_target(args.output, args.recording)
    window, clamped = _window(args)
    rec = window.recording
    meta = rec.metadata
    cut = (
        f"trimmed by labstand to t = {window.start_s:g} … {window.end_s:g} s of "
        f"{args.recording.name} (which spans {window.first_s:g} … {window.last_s:g} s)"
        + (f"; --end {args.end:g} s was past its end" if clamped else "")
    )
    note = f"{meta.operator_note}; {cut}" if meta.operator_note else cut
    write_recording(rec, args.output, with_changes(meta, operator_note=note))
    print(
        f"Trimmed {args.recording} → {args.output}: {len(rec.gauges)} samples, "
        f"t = {window.start_s:g} … {window.end_s:g} s, {len(rec.events_array)} event(s) kept"
    )
    if clamped:
        print(f"  note: --end {args.end:g} s is past the end; cut at the end, {window.end_s:g} s")
    return 0


def _window(args: argparse.Namespace) -> tuple[Window, bool]:
    """The window asked for; an --end past the recording's end is clamped to it (True)."""
    from recordings.window import WindowError, read_window

    try:
        return read_window(args.recording, args.start, args.end), False
    except WindowError:
        if args.end is None:
            raise
        to_end = read_window(args.recording, args.start, None)  # its own errors, if any
        if args.end <= to_end.last_s:  # not past the end: the first complaint stands
            raise
        return to_end, True
