"""``labstand info``: what a recording holds."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from labstand.terminal import printable


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand info``."""
    parser = sub.add_parser(
        "info",
        help="duration, channels, rates, lost samples, metadata and events of a recording",
        description="Summarise a recording (.mcap, .h5, or a .csv/.tdms run). JSON keys: "
        "duration_s, lost_samples, channels (name -> {unit, rate_hz, samples}), metadata, "
        "event_list ([{t_s, kind, text}]: why the run ended), ...",
    )
    parser.add_argument("recording", type=Path, metavar="REC")
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read and summarise."""
    from recordings import open_recording
    from recordings.convert import summary

    recording = open_recording(args.recording, log_repairs=False)
    info = summary(recording)
    info["mass_kg"] = recording.metadata.mass_kg
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        _print(info)
    return 0


def _say(line: str) -> None:
    """One line of the text output; the file's own text escaped (labstand.terminal)."""
    print(printable(line))


def _print(info: dict[str, Any]) -> None:
    meta = info["metadata"]
    _say(f"{info['path']}: schema {meta['schema_version']}, backend {meta['backend']}")
    _say(
        f"  {info['duration_s']:.3f} s from {info['start_time_utc']}, {info['samples']} samples, "
        f"{info['lost_samples']} lost in {info['gaps']} gap(s)"
    )
    _say(f"  written by labstand {meta['software_version']} on {meta['host'] or '?'}")
    if meta["signal"]:
        sig = meta["signal"]
        situation = f"situation {sig['situation']}: " if sig.get("situation") else ""
        _say(
            f"  signal {situation}{sig['shape']}, A = {sig['amplitude_mm']:g} mm, "
            f"f = {sig['frequency_hz']:g} Hz, {sig['cycles']} cycle(s)"
        )
    mass = info["mass_kg"]
    print(f"  mass {mass:g} kg" if mass is not None else "  mass: not stored")
    for effect in meta["effects"]:
        params = ", ".join(f"{k} = {v:g}" for k, v in effect["params"].items())
        print(f"  simulated effect {effect['name']}" + (f": {params}" if params else ""))
    who = [f"{k} {meta[k]}" for k in ("operator", "sample") if meta.get(k)]
    if meta.get("tags"):
        who.append("tags " + ", ".join(meta["tags"]))
    if who:
        print(f"  {'; '.join(who)}")
    if meta.get("run_id"):
        print(f"  run {meta['run_id']}")
    if meta["operator_note"]:
        _say(f"  note: {meta['operator_note']}")
    _say("  channels:")
    for name, ch in info["channels"].items():
        rate = f"{ch['rate_hz']:g} Hz" if ch["rate_hz"] else "irregular"
        _say(f"    {name:<22} {ch['unit'] or '-':<5} {rate:>10} {ch['samples']:>9} samples")
    for line in info["repairs"]:
        _say(f"  repaired: {line}")
    _print_events(info["event_list"])


#: Events listed by the text output; ``labstand cat REC --events`` prints them all.
SHOWN_EVENTS = 20
#: Kinds that end a run.
ENDINGS = ("stop", "estop", "fault")


def _print_events(events: list[dict[str, Any]]) -> None:
    if not events:
        _say("  events: none")
        return
    _say(f"  events ({len(events)}):")
    shown = events if len(events) <= SHOWN_EVENTS else events[: SHOWN_EVENTS - 1]
    for e in shown:
        _say(f"    {e['t_s']:12.6f} s  {e['kind']:<7} {' '.join(e['text'].split())}")
    if len(shown) < len(events):
        _say(f"    … {len(events) - len(shown)} more (labstand cat REC --events)")
    ending = next((e for e in reversed(events) if e["kind"] in ENDINGS), None)
    if ending is not None:
        _say(f"  ended: {ending['kind']} at {ending['t_s']:.6f} s: {ending['text']}")
