"""``labstand doctor``: is a recording whole, and what would ``recover`` do? Writes nothing."""

from __future__ import annotations

import argparse
from pathlib import Path

from labstand.errors import CommandError, ExitCode, require_file


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand doctor``."""
    parser = sub.add_parser(
        "doctor",
        description="Check FILE as every command reads it (checksums, schema, times) and say "
        "what is wrong; for a damaged file, what 'labstand recover FILE -o FIXED' would keep "
        "and repair. Writes nothing. Exit 0: intact; 1: damaged (recover repairs it); 2: not "
        "a readable recording at all.",
    )
    parser.add_argument("file", type=Path, metavar="FILE", help="a recording (any format)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read strictly; if that fails, read as recover would, and tell."""
    from recordings import RecordingError, open_recording

    path: Path = args.file
    require_file(path)
    try:
        rec = open_recording(path, log_repairs=False)
    except RecordingError as err:
        problem = " ".join(str(err).split())
    else:
        print(
            f"{path}: intact: {len(rec.gauges)} samples, {rec.duration_s:.3f} s, "
            f"{rec.lost_samples} lost in gaps, {len(rec.events_array)} event(s); "
            "nothing for recover to do"
        )
        return ExitCode.OK
    try:
        salvaged = open_recording(path, salvage=True, log_repairs=False)
    except RecordingError as err:
        again = " ".join(str(err).split())
        why = problem if again == problem else f"{problem}; read as recover would: {again}"
        raise CommandError(f"{why} (recover cannot read it either)", ExitCode.USAGE) from None
    print(f"{path}: damaged: {problem}")
    print(
        f"  labstand recover {path} -o FIXED would keep {len(salvaged.gauges)} samples "
        f"({salvaged.duration_s:.3f} s, {salvaged.lost_samples} lost in gaps) and "
        f"{len(salvaged.events_array)} event(s):"
    )
    for line in salvaged.repairs or ["(no repair listed: the strict reading's complaint stands)"]:
        print(f"    {line}")
    return ExitCode.FAILURE
