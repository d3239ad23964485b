"""``labstand convert``: one recording format into another (MCAP, HDF5, CSV, Parquet)."""

from __future__ import annotations

import argparse
from pathlib import Path

from labstand.errors import CommandError, ExitCode
from labstand.targets import FILE


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand convert``."""
    parser = sub.add_parser(
        "convert",
        help="convert a recording between MCAP, HDF5, CSV and Parquet",
        description="Convert recording A into B; the suffixes pick the formats (.mcap, .h5, "
        ".hdf5, .csv, .parquet). MCAP and HDF5 copy every stream and the metadata as they "
        "are. CSV and Parquet hold one table on the gauge clock (t, x_mm, u_mm, F_N, "
        "x_cmd_mm, seq, flags; units in the CSV header and the Parquet schema) and carry the "
        "metadata, events and drive polls along (CSV: '# labstand-...' preamble lines; "
        "Parquet: key-value metadata), so they convert back losslessly.",
    )
    parser.add_argument("source", type=Path, metavar="A", help="recording to read")
    parser.add_argument("target", type=Path, metavar="B", help="recording to write")
    parser.set_defaults(func=run, outputs={"target": FILE})


def writable_suffixes() -> list[str]:
    """Every suffix ``write_recording`` writes."""
    from recordings.formats import suffixes

    return suffixes("write", "table")


def check_target(target: Path, source: Path) -> None:
    """Refuse (exit 2) a target that cannot be written or would overwrite the source."""
    if target.suffix.lower() not in writable_suffixes():
        raise CommandError(
            f"{target}: cannot write {target.suffix or 'files without a suffix'!r}; "
            f"use one of {', '.join(writable_suffixes())}",
            ExitCode.USAGE,
        )
    if source.resolve() == target.resolve():
        raise CommandError(f"{target}: would overwrite the source", ExitCode.USAGE)


def run(args: argparse.Namespace) -> int:
    """Read A, write B."""
    import numpy as np

    from recordings import open_recording
    from recordings.convert import write_recording

    check_target(args.target, args.source)
    recording = open_recording(args.source)
    write_recording(recording, args.target)
    print(f"Converted {args.source} → {args.target} ({len(recording.gauges)} samples)")
    command, gauges = recording.command, recording.gauges
    table = args.target.suffix.lower() in {".csv", ".parquet"}
    if table and len(command) and not np.array_equal(command["t_ns"], gauges["t_ns"]):
        print(
            "  note: the command has a clock of its own; written at the gauge times, interpolated"
        )
    return 0
