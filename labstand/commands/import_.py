"""``labstand import``: a CSV or LabVIEW TDMS run into a recording (.mcap or .h5)."""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from labstand.commands.common import (
    add_metadata_options,
    add_stand_options,
    config_with_mass,
    load_stand,
    metadata_options,
)
from labstand.errors import CommandError, ExitCode, require_file
from labstand.targets import FILE

MAP_HELP = """\
which column holds which quantity: FIELD=COLUMN or FIELD=COLUMN[UNIT], repeatable.
FIELD: time, x (drive position), u (weight displacement), F (fibre force), x_cmd
(drive command). COLUMN: the CSV header, or the TDMS channel as Group/Channel (or
Channel). UNIT: s, ms, us, ns | m, mm, cm, um | N, kN, mN; without one, the unit in
the column name's brackets, the TDMS unit_string, or the schema's (s, mm, N).
Example: --map time=Time[ms] --map F=Force[kN]. Default columns: t_s, x_mm, u_mm, F_N."""

EPILOG = """\
CSV from a spreadsheet (German locale, Windows):
  labstand import run.csv --decimal , --encoding cp1252 -o run.mcap
Lines starting with '#' before the header are the file's preamble: skipped, and kept in
the recording's operator note. --skip-rows N skips N lines first, whatever they hold.
The weight the run was made with: --mass-kg M (else the stand's default weight); it is
stored with the stand in the recording, and replay, table1 and diagnose use it."""


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand import``."""
    parser = sub.add_parser(
        "import",
        description="Import a run exported from another tool (CSV) or recorded by the old "
        "LabVIEW stand (TDMS) into a recording (-o OUT.mcap or OUT.h5). Units are "
        "converted to the schema's (mm, N); a truncated TDMS file is trimmed to its "
        "shortest channel, and the recording says so.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", type=Path, metavar="FILE", help="the .csv or .tdms file")
    parser.add_argument(
        "--map", action="append", default=[], metavar="FIELD=COLUMN[UNIT]", help=MAP_HELP
    )
    parser.add_argument("--note", default="", help="operator note stored in the metadata")
    add_metadata_options(parser)
    parser.add_argument(
        "--mass-kg", type=float, help="weight mass of the run, kg (default: the stand's)"
    )
    add_stand_options(parser)
    csv = parser.add_argument_group("CSV")
    csv.add_argument(
        "--decimal",
        default=".",
        choices=(".", ","),
        help="decimal mark; with ',' the separator must be ';' or tab (default: .)",
    )
    csv.add_argument(
        "--skip-rows", type=int, default=0, metavar="N", help="skip N lines at the top (0)"
    )
    csv.add_argument(
        "--comment",
        default="#",
        metavar="CHAR",
        help="lines starting with CHAR are skipped; '' for none (default: #)",
    )
    csv.add_argument(
        "--encoding", default="utf-8", help="text encoding, e.g. latin-1, cp1252 (utf-8)"
    )
    parser.add_argument(
        "-o", "--output", type=Path, required=True, help="the recording (.mcap or .h5)"
    )
    parser.set_defaults(func=run, outputs={"output": FILE})


def run(args: argparse.Namespace) -> int:
    """Read, map, check, write."""
    from recordings.convert import summary, with_changes, write_recording
    from recordings.csvio import CsvOptions, read_csv
    from recordings.foreign import parse_mapping
    from recordings.tdmsio import read_tdms

    require_file(args.file)  # before its suffix: "no such file" says more
    suffix = args.file.suffix.lower()
    if suffix not in {".csv", ".tdms"}:
        raise CommandError(
            f"{args.file}: cannot import {args.file.suffix!r}; use .csv or .tdms", ExitCode.USAGE
        )
    if args.mass_kg is not None and not args.mass_kg > 0:
        raise CommandError(f"--mass-kg must be > 0 kg, got {args.mass_kg:g}", ExitCode.USAGE)
    mapping = parse_mapping(args.map)
    stand = None
    if args.stand is not None or args.mass_kg is not None:
        config = load_stand(args)
        mass = args.mass_kg if args.mass_kg is not None else config.default_mass_kg
        stand = config_with_mass(config, mass)
    if suffix == ".csv":
        options = CsvOptions(args.decimal, args.skip_rows, args.comment, args.encoding)
        recording = read_csv(args.file, mapping=mapping, stand_config=stand, options=options)
    else:
        recording = read_tdms(args.file, mapping=mapping, stand_config=stand)
    recording.check()
    meta = recording.metadata
    if args.note:
        meta = with_changes(meta, operator_note=f"{args.note} ({meta.operator_note})")
    meta = with_changes(meta, **metadata_options(args))
    write_recording(recording, args.output, meta)
    info = summary(recording)
    print(
        f"Imported {info['samples']} samples ({info['duration_s']:.3f} s at "
        f"{meta.sample_rate_hz:g} Hz) from {args.file} into {args.output}"
    )
    told = _told(args, stand is None and meta.stand_config != load_stand(args).to_dict())
    print(f"  weight {_weight(meta.stand_config):g} kg ({told}), stored with it")
    for line in recording.repairs:
        print(f"  repaired: {line}")
    return 0


def _weight(stand: Mapping[str, Any]) -> float:
    return float(stand["weights_kg"][stand["weight"]["default"]])


def _told(args: argparse.Namespace, from_file: bool) -> str:
    if args.mass_kg is not None:
        return "--mass-kg"
    if args.stand is not None:
        return f"default weight of {args.stand}"
    if from_file:
        return "the labstand metadata in the file"
    return "the paper stand's default weight; give --mass-kg if another hung"
