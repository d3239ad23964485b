"""``labstand info``: what a recording holds."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand info``."""
    parser = sub.add_parser(
        "info",
        description="Summarise a recording (.mcap, .h5, or a .csv/.tdms run). JSON keys: "
        "duration_s, lost_samples, channels (name -> {unit, rate_hz, samples}), metadata, ...",
    )
    parser.add_argument("recording", type=Path, metavar="REC")
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read and summarise."""
    from recordings import open_recording
    from recordings.convert import summary

    info = summary(open_recording(args.recording, log_repairs=False))
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        _print(info)
    return 0


def _print(info: dict[str, Any]) -> None:
    meta = info["metadata"]
    print(f"{info['path']}: schema {meta['schema_version']}, backend {meta['backend']}")
    print(
        f"  {info['duration_s']:.3f} s from {info['start_time_utc']}, {info['samples']} samples, "
        f"{info['lost_samples']} lost in {info['gaps']} gap(s)"
    )
    print(f"  written by labstand {meta['software_version']} on {meta['host'] or '?'}")
    if meta["signal"]:
        sig = meta["signal"]
        print(
            f"  signal {sig['shape']}, A = {sig['amplitude_mm']:g} mm, "
            f"f = {sig['frequency_hz']:g} Hz, {sig['cycles']} cycle(s)"
        )
    if meta["operator_note"]:
        print(f"  note: {meta['operator_note']}")
    print("  channels:")
    for name, ch in info["channels"].items():
        rate = f"{ch['rate_hz']:g} Hz" if ch["rate_hz"] else "irregular"
        print(f"    {name:<22} {ch['unit'] or '-':<5} {rate:>10} {ch['samples']:>9} samples")
    for line in info["repairs"]:
        print(f"  repaired: {line}")
