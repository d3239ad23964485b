"""The ``labstand`` command: argument parsing and the one place errors become exit codes.

Each sub-command lives in ``labstand/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from drivers.limits import LimitError
from labstand import __version__
from labstand.errors import CommandError, ExitCode
from recordings.errors import RecordingError
from sim.config import ConfigError
from sim.errors import SimulationError

#: Sub-command modules, in the order ``--help`` lists them.
COMMANDS = [
    "simulate",
    "model",
    "stand_sim",
    "run",
    "replay",
    "compare",
    "table1",
    "info",
    "import_",
    "convert",
    "recover",
    "diagnose",
    "diagnose_check",
]

log = logging.getLogger("labstand")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser (all sub-commands)."""
    parser = argparse.ArgumentParser(
        prog="labstand",
        description="Run the fibre stand, record it, and compare it with the model.",
    )
    parser.add_argument("--version", action="version", version=f"labstand {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log details to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"labstand.commands.{name}").register(sub)
    return parser


_PREFIXES = {
    ExitCode.REFUSED: "refused",
    ExitCode.ESTOP: "e-stop",
    ExitCode.INTERRUPTED: "interrupted",
}


def _error_code(err: Exception) -> ExitCode:
    if isinstance(err, CommandError):
        return err.code
    if isinstance(err, LimitError):
        return ExitCode.REFUSED
    if isinstance(err, ConfigError | SimulationError | RecordingError | ValueError):
        return ExitCode.USAGE
    return ExitCode.FAILURE


def main(argv: Sequence[str] | None = None) -> int:
    """Run labstand with argv (without the program name); returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        code: int = args.func(args)
    except KeyboardInterrupt:
        print("labstand: interrupted", file=sys.stderr)
        return ExitCode.INTERRUPTED
    except (
        CommandError,
        LimitError,
        ConfigError,
        SimulationError,
        RecordingError,
        OSError,
        ValueError,
    ) as err:
        if args.verbose:
            log.exception("command failed")
        code = _error_code(err)
        prefix = _PREFIXES.get(code, "error")
        print(f"labstand: {prefix}: {err}", file=sys.stderr)
        return code
    return code


def entry_point() -> None:
    """Console-script entry."""
    sys.exit(main())
