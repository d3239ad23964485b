"""``labstand convert``: one recording format into another (MCAP ↔ HDF5), losslessly."""

from __future__ import annotations

import argparse
from pathlib import Path

from labstand.errors import CommandError, ExitCode


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand convert``."""
    parser = sub.add_parser(
        "convert",
        description="Convert recording A into B; the suffixes pick the formats (.mcap, .h5, "
        ".hdf5). Every stream and the metadata are copied as they are.",
    )
    parser.add_argument("source", type=Path, metavar="A", help="recording to read")
    parser.add_argument("target", type=Path, metavar="B", help="recording to write")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read A, write B."""
    from recordings import open_recording
    from recordings.convert import write_recording

    if args.source.resolve() == args.target.resolve():
        raise CommandError(f"{args.target}: would overwrite the source", ExitCode.USAGE)
    recording = open_recording(args.source)
    write_recording(recording, args.target)
    print(f"Converted {args.source} → {args.target} ({len(recording.gauges)} samples)")
    return 0
