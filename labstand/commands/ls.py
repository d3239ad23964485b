"""``labstand ls``: the recordings of a folder, from their metadata alone (a table or JSON)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from labstand.errors import require_file

#: Columns of the table: title, width (the last one takes the rest of the line).
NOTE_WIDTH = 40


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand ls``."""
    parser = sub.add_parser(
        "ls",
        description="List the recordings in DIR (or the files given) with their date, "
        "duration, signal, mass, operator, sample and note, oldest first. Only each file's "
        "metadata and time span are read (its index or footer), so a thousand recordings "
        "list in about a second. Filters keep the recordings that match every one given.",
    )
    parser.add_argument("paths", type=Path, nargs="*", metavar="DIR", help="folders or files (.)")
    parser.add_argument("-r", "--recursive", action="store_true", help="look into sub-folders")
    parser.add_argument("--operator", metavar="NAME", help="only this operator's recordings")
    parser.add_argument("--sample", metavar="ID", help="only those of this sample (fibre)")
    parser.add_argument(
        "--tag", action="append", default=[], metavar="TAG", help="only those with this tag "
        "(repeatable: all of them)"
    )  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print a JSON list")
    parser.set_defaults(func=run)


def files(paths: list[Path], recursive: bool) -> list[Path]:
    """The files of the folders (and the files) given, in name order."""
    from recordings.catalog import SUFFIXES

    out: list[Path] = []
    for path in paths or [Path(".")]:
        if path.is_dir():
            found = path.rglob("*") if recursive else path.iterdir()
            out += sorted(p for p in found if p.suffix.lower() in SUFFIXES and p.is_file())
        else:
            require_file(path)  # a missing one: exit 2 ("no such file: x")
            out.append(path)
    return out


def keep(row: dict[str, Any], args: argparse.Namespace) -> bool:
    """Whether a row passes the filters (case-insensitive, whole words)."""
    if "error" in row:
        return not (args.operator or args.sample or args.tag)
    for key in ("operator", "sample"):
        wanted = getattr(args, key)
        if wanted is not None and row[key].casefold() != wanted.casefold():
            return False
    tags = {t.casefold() for t in row["tags"]}
    return all(t.casefold() in tags for t in args.tag)


def run(args: argparse.Namespace) -> int:
    """Read every file's metadata, filter, print."""
    from recordings.catalog import entries

    rows = [e.to_dict() for e in entries(files(args.paths, args.recursive))]
    rows = [r for r in rows if keep(r, args)]
    rows.sort(key=lambda r: (r.get("start_time_utc", "~"), r["path"]))
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    if not rows:
        print("no recordings")
        return 0
    table = [_cells(r) for r in rows]
    titles = ("date (UTC)", "duration", "signal", "mass", "operator", "sample", "file", "note")
    widths = [max(len(t), *(len(c[i]) for c in table)) for i, t in enumerate(titles[:-1])]
    for cells in [titles, *table]:
        line = "  ".join(f"{c:<{w}}" for c, w in zip(cells, widths, strict=False))
        print(f"{line}  {cells[-1]}".rstrip())
    return 0


def _cells(row: dict[str, Any]) -> tuple[str, ...]:
    name = row["path"]
    if "error" in row:
        return ("?", "?", "?", "?", "", "", name, f"unreadable: {row['error']}"[:NOTE_WIDTH])
    date = row["start_time_utc"][:16].replace("T", " ")
    duration = "?" if row["duration_s"] is None else f"{row['duration_s']:.1f} s"
    mass = "?" if row["mass_kg"] is None else f"{row['mass_kg']:g} kg"
    note = " ".join(row["note"].split())
    if row["tags"]:
        note = f"[{', '.join(row['tags'])}] {note}"
    if len(note) > NOTE_WIDTH:
        note = note[: NOTE_WIDTH - 1] + "…"
    return (
        date,
        duration,
        _signal(row["signal"]),
        mass,
        row["operator"],
        row["sample"],
        name,
        note,
    )


def _signal(signal: dict[str, Any] | None) -> str:
    if not signal:
        return "-"
    if signal.get("situation"):
        return f"situation {signal['situation']}"
    return (
        f"{signal.get('shape', '?')} {signal.get('amplitude_mm', 0):g} mm "
        f"{signal.get('frequency_hz', 0):g} Hz"
    )
