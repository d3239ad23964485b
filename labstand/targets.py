"""What a command writes, checked before it does any work: nothing is overwritten.

A command names its output options once, ``parser.set_defaults(outputs={"output":
FILE, "report": FOLDER})``; ``labstand.cli`` then adds ``--force`` to that command and
calls ``check_outputs`` before the command runs, so a repeated command line cannot
replace an earlier recording, and a run refuses before its drive moves. A missing
parent folder is refused the same way for every output (nothing creates it silently).
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Mapping
from pathlib import Path

from labstand.errors import CommandError, ExitCode

__all__ = ["FILE", "FOLDER", "add_force", "check_output", "check_outputs"]

FILE = "file"
FOLDER = "folder"


def add_force(parser: argparse.ArgumentParser) -> None:
    """--force: replace outputs that exist."""
    parser.add_argument(
        "--force", action="store_true", help="replace an output that exists (default: refuse)"
    )


def check_output(path: Path, force: bool, kind: str = FILE, option: str = "") -> None:
    """Refuse (exit 2) an output that exists (unless ``force``) or whose folder does not."""
    named = f"{option} {path}" if option else str(path)
    parent = path.parent
    if not parent.is_dir():
        why = f"{parent} is not a folder" if parent.exists() else f"no such folder {parent}"
        raise CommandError(f"{named}: cannot write: {why}", ExitCode.USAGE)
    if kind == FOLDER and path.exists() and not path.is_dir():
        raise CommandError(f"{named}: is a file, not a folder", ExitCode.USAGE)
    if kind == FILE and path.is_dir():
        raise CommandError(f"{named}: is a folder, not a file", ExitCode.USAGE)
    if path.exists() and not force:
        raise CommandError(
            f"{named}: exists; nothing written (give --force to replace it)", ExitCode.USAGE
        )


def check_outputs(args: argparse.Namespace, outputs: Mapping[str, str]) -> None:
    """``check_output`` for each declared output option that was given."""
    force = bool(getattr(args, "force", False))
    for name, kind in outputs.items():
        value = getattr(args, name, None)
        for path in _paths(value):
            check_output(path, force, kind, _option(name))


def _paths(value: object) -> Iterable[Path]:
    if isinstance(value, Path):
        return [value]
    if isinstance(value, list | tuple):
        return [v for v in value if isinstance(v, Path)]
    return []


def _option(name: str) -> str:
    return "" if name in {"output", "target"} else "--" + name.replace("_", "-")
