"""The ``labstand`` command: argument parsing and the one place errors become exit codes.

Each sub-command lives in ``labstand/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
from collections.abc import Sequence
from typing import NoReturn

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
    "play",
    "compare",
    "table1",
    "info",
    "import_",
    "convert",
    "cat",
    "trim",
    "recover",
    "diagnose",
    "diagnose_check",
]

log = logging.getLogger("labstand")


class _Parser(argparse.ArgumentParser):
    """argparse, with a usage error in one line and a hint to --help (exit 2)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser (all sub-commands)."""
    parser = _Parser(
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


def _subparser(parser: argparse.ArgumentParser, name: str | None) -> argparse.ArgumentParser | None:
    """The sub-command's parser (for its usage errors), or None.

    argparse has no public way to reach its sub-parsers; its private ``_subparsers`` group
    has been stable since Python 3.2.
    """
    for action in parser._subparsers._group_actions if parser._subparsers else ():
        if isinstance(action, argparse._SubParsersAction) and name in action.choices:
            found: argparse.ArgumentParser = action.choices[name]
            return found
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """Run labstand with argv (without the program name); returns the exit code."""
    parser = build_parser()
    words = list(sys.argv[1:] if argv is None else argv)
    # -v / --verbose anywhere, before or after the sub-command (up to a "--").
    end = words.index("--") if "--" in words else len(words)
    verbose = any(w in ("-v", "--verbose") for w in words[:end])
    words = [w for i, w in enumerate(words) if i >= end or w not in ("-v", "--verbose")]
    args, extra = parser.parse_known_args(words)
    if extra:  # name the command whose --help would have told
        command = _subparser(parser, getattr(args, "command", None)) or parser
        command.error(f"unrecognized arguments: {' '.join(extra)}")
    args.verbose = verbose
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        code: int = args.func(args)
    except BrokenPipeError:
        # The reader went away (`labstand info X | head -1`): end quietly, as Unix tools
        # do; stdout goes to /dev/null so the interpreter's final flush cannot fail too.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return ExitCode.OK
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
    code = main()
    try:
        sys.stdout.flush()  # what is still buffered, while a closed pipe can be caught
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    sys.exit(code)
