"""``labstand import``: a CSV or LabVIEW TDMS run into a recording (.mcap or .h5)."""

from __future__ import annotations

import argparse
import importlib
from pathlib import Path

from labstand.commands.common import add_stand_options, load_stand
from labstand.errors import CommandError, ExitCode

#: suffix -> the module and function that read it (imported only when the command runs)
_READERS = {".csv": ("recordings.csvio", "read_csv"), ".tdms": ("recordings.tdmsio", "read_tdms")}

MAP_HELP = """\
which column holds which quantity: FIELD=COLUMN or FIELD=COLUMN[UNIT], repeatable.
FIELD: time, x (drive position), u (weight displacement), F (fibre force), x_cmd
(drive command). COLUMN: the CSV header, or the TDMS channel as Group/Channel (or
Channel). UNIT: s, ms, us, ns | m, mm, cm, um | N, kN, mN; without one, the unit in
the column name's brackets, the TDMS unit_string, or the schema's (s, mm, N).
Example: --map time=Time[ms] --map F=Force[kN]. Default columns: t_s, x_mm, u_mm, F_N."""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand import``."""
    parser = sub.add_parser(
        "import",
        description="Import a run exported from another tool (CSV) or recorded by the old "
        "LabVIEW stand (TDMS) into a recording (-o OUT.mcap or OUT.h5). Units are "
        "converted to the schema's (mm, N); a truncated TDMS file is trimmed to its "
        "shortest channel, and the recording says so.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", type=Path, metavar="FILE", help="the .csv or .tdms file")
    parser.add_argument(
        "--map", action="append", default=[], metavar="FIELD=COLUMN[UNIT]", help=MAP_HELP
    )
    parser.add_argument("--note", default="", help="operator note stored in the metadata")
    add_stand_options(parser)
    parser.add_argument(
        "-o", "--output", type=Path, required=True, help="the recording (.mcap or .h5)"
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read, map, check, write."""
    from recordings.convert import summary, with_changes, write_recording
    from recordings.foreign import parse_mapping

    where = _READERS.get(args.file.suffix.lower())
    if where is None:
        raise CommandError(
            f"{args.file}: cannot import {args.file.suffix!r}; use .csv or .tdms", ExitCode.USAGE
        )
    reader = getattr(importlib.import_module(where[0]), where[1])
    mapping = parse_mapping(args.map)
    config = load_stand(args)
    recording = reader(args.file, mapping=mapping, stand_config=config.to_dict())
    recording.check()
    meta = recording.metadata
    if args.note:
        meta = with_changes(meta, operator_note=f"{args.note} ({meta.operator_note})")
    write_recording(recording, args.output, meta)
    info = summary(recording)
    print(
        f"Imported {info['samples']} samples ({info['duration_s']:.3f} s at "
        f"{meta.sample_rate_hz:g} Hz) from {args.file} into {args.output}"
    )
    for line in recording.repairs:
        print(f"  repaired: {line}")
    return 0
