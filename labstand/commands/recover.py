"""``labstand recover``: everything readable from a recording whose writer was killed."""

from __future__ import annotations

import argparse
from pathlib import Path

from labstand.errors import CommandError, ExitCode
from labstand.targets import FILE


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand recover``."""
    parser = sub.add_parser(
        "recover",
        description="Read BROKEN as far as it is intact (MCAP: every complete chunk, each "
        "CRC-checked; HDF5: the state of its last flush) and write a clean recording to "
        "-o FIXED (format by suffix). What was repaired is printed and stored as a "
        "'repair' event in FIXED.",
    )
    parser.add_argument("broken", type=Path, metavar="BROKEN", help="the damaged recording")
    parser.add_argument("-o", "--output", type=Path, required=True, metavar="FIXED")
    parser.set_defaults(func=run, outputs={"output": FILE})


def run(args: argparse.Namespace) -> int:
    """Salvage and rewrite."""
    from recordings import open_recording
    from recordings.convert import write_recording

    if args.broken.resolve() == args.output.resolve():
        raise CommandError(f"{args.output}: would overwrite the damaged file", ExitCode.USAGE)
    recording = open_recording(args.broken, salvage=True, log_repairs=False)
    write_recording(recording, args.output)
    print(
        f"Recovered {len(recording.gauges)} samples ({recording.duration_s:.3f} s, "
        f"{recording.lost_samples} lost in gaps) from {args.broken} into {args.output}"
    )
    for line in recording.repairs or ["nothing to repair: the file was intact"]:
        print(f"  {line}")
    return 0
