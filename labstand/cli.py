"""The ``labstand`` command: argument parsing and the one place errors become exit codes.

Each sub-command lives in ``labstand/commands/<module>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.

Start-up stays quick (docs/benchmarks.md): the top-level ``--help`` is built from the
static ``COMMANDS`` table alone, and only the chosen command's module is imported; the
command modules import their heavy parts (numba, scipy, pandas, matplotlib, h5py, ...)
inside the function that runs the command.
"""

from __future__ import annotations

import argparse
import importlib
import keyword
import logging
import os
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from drivers.limits import LimitError
from labstand.errors import CommandError, ExitCode, describe_os_error
from labstand.interrupts import Terminated, sigterm_raises
from labstand.stands import find_stand
from labstand.targets import add_force, check_outputs
from recordings.errors import RecordingError
from sim.errors import SimulationError

#: Sub-commands, in the order ``--help`` lists them: name → one-line help. A command
#: NAME lives in ``labstand.commands.NAME`` ("-" → "_", a Python keyword gets a "_"
#: suffix: ``import`` → ``import_``); adding one is one line here.
COMMANDS: dict[str, str] = {
    "simulate": "simulate a run with the baseline model",
    "model": "properties of the baseline model",
    "stand-sim": "run the simulated stand (Modbus drive + 2 kHz gauges) on its own",
    "run": "run a test on the stand (or the simulated stand) and record it",
    "replay": "feed recordings' drive motion into the model and compare",
    "play": "play a recording to Foxglove (WebSocket), with the model beside it",
    "compare": "compare two recordings (e.g. two runs of one situation)",
    "table1": "Table 1 of the paper: R per channel for two parameter sets",
    "info": "duration, channels, rates, lost samples and metadata of a recording",
    "ls": "list the recordings of a folder (date, duration, signal, mass, operator, sample)",
    "import": "import a CSV or TDMS run as a recording",
    "convert": "convert a recording into MCAP, HDF5, CSV or Parquet",
    "cat": "print samples or events of a time window as CSV text",
    "trim": "cut a time window out of a recording into a new one",
    "plot": "a quick look at a recording: x, u and F over time as a PNG",
    "recover": "recover a recording whose writer was killed",
    "doctor": "check a recording and say what recover would do (writes nothing)",
    "diagnose": "find which unmodelled effect explains the gap between model and recordings",
    "diagnose-check": "score the diagnosis on generated recordings whose effect is withheld",
    "plan": "the next test: the admissible motion that best separates a diagnosis' rivals",
    "campaign": "run, diagnose, plan the next test and run it, until the answer is certain",
    "completion": "print a shell completion script (bash, zsh, tcsh)",
}

log = logging.getLogger("labstand")


class _Parser(argparse.ArgumentParser):
    """argparse, with a usage error in one line and a hint to --help (exit 2)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


if TYPE_CHECKING:
    _SubParsers = argparse._SubParsersAction[argparse.ArgumentParser]
else:  # not subscriptable at run time
    _SubParsers = argparse._SubParsersAction


class _Commands(_SubParsers):
    """The sub-command action: a command's one-line help comes from ``COMMANDS``."""

    def add_parser(self, name: str, **kwargs: Any) -> argparse.ArgumentParser:
        kwargs.setdefault("help", COMMANDS.get(name))
        return super().add_parser(name, **kwargs)


class _Version(argparse.Action):
    """--version, reading the installed version only when asked (importlib.metadata)."""

    def __call__(self, parser: argparse.ArgumentParser, *_: object, **__: object) -> None:
        import labstand

        print(f"labstand {labstand.__version__}")
        parser.exit()


def command_module(name: str) -> str:
    """The module that implements sub-command ``name``."""
    module = name.replace("-", "_")
    return f"labstand.commands.{module}{'_' if keyword.iskeyword(module) else ''}"


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser, with ``command``'s full sub-parser (all of them if None).

    The other sub-commands get a stub (name and one-line help) so that the top-level
    ``--help`` lists them and a mistyped name is refused with the list of choices,
    without importing their modules.
    """
    parser = _Parser(
        prog="labstand",
        description="Run the fibre stand, record it, and compare it with the model.",
    )
    parser.add_argument(
        "-V", "--version", action=_Version, nargs=0, help="show the version and exit"
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log details to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, action=_Commands)
    for name in COMMANDS:
        if command is None or name == command:
            importlib.import_module(command_module(name)).register(sub)
            if sub.choices[name].get_default("outputs"):
                add_force(sub.choices[name])
        else:
            sub.add_parser(name, add_help=False)
    return parser


def _chosen(words: Sequence[str]) -> str | None:
    """The sub-command named in ``words`` (the first word that is not an option)."""
    for word in words:
        if word == "--":
            return None
        if not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


_PREFIXES = {
    ExitCode.REFUSED: "refused",
    ExitCode.ESTOP: "e-stop",
    ExitCode.INTERRUPTED: "interrupted",
    ExitCode.TERMINATED: "terminated",
}


def describe(err: Exception) -> tuple[str, ExitCode]:
    """The one place an exception becomes the user's line and the exit code."""
    if isinstance(err, CommandError):
        code = err.code
    elif isinstance(err, LimitError):
        code = ExitCode.REFUSED
    elif isinstance(err, OSError):
        text, code = describe_os_error(err)
        return f"labstand: {_PREFIXES.get(code, 'error')}: {text}", code
    # ConfigError (sim.config, not imported here: it pulls scipy) is a ValueError too.
    elif isinstance(err, SimulationError | RecordingError | ValueError):
        code = ExitCode.USAGE
    else:
        code = ExitCode.FAILURE
    text = " ".join(str(err).split()) or type(err).__name__  # one line, whatever it holds
    return f"labstand: {_PREFIXES.get(code, 'error')}: {text}", code


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
    words = list(sys.argv[1:] if argv is None else argv)
    # -v / --verbose anywhere, before or after the sub-command (up to a "--").
    end = words.index("--") if "--" in words else len(words)
    verbose = any(w in ("-v", "--verbose") for w in words[:end])
    words = [w for i, w in enumerate(words) if i >= end or w not in ("-v", "--verbose")]
    # Only the chosen command's module is imported ("": none, for the top-level --help).
    parser = build_parser(_chosen(words) or "")
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
        if getattr(args, "find_stand", False) and args.stand is None:
            args.stand, args.stand_origin = find_stand()
        check_outputs(args, getattr(args, "outputs", None) or {})  # before any work
        with sigterm_raises():
            code: int = args.func(args)
    except BrokenPipeError:
        # The reader went away (`labstand info X | head -1`): end quietly, as Unix tools
        # do; stdout goes to /dev/null so the interpreter's final flush cannot fail too.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return ExitCode.OK
    except Terminated:
        print("labstand: terminated (SIGTERM)", file=sys.stderr)
        return ExitCode.TERMINATED
    except KeyboardInterrupt:
        print("labstand: interrupted", file=sys.stderr)
        return ExitCode.INTERRUPTED
    except (
        CommandError,
        LimitError,
        SimulationError,
        RecordingError,
        OSError,
        ValueError,
    ) as err:
        if args.verbose:
            log.exception("command failed")
        line, code = describe(err)
        print(line, file=sys.stderr)
        return code
    except Exception as err:  # a bug of ours: still one line; -v has the traceback
        if args.verbose:
            log.exception("command failed")
        what = " ".join(str(err).split())
        print(
            f"labstand: error: internal error ({type(err).__name__}: {what}); "
            "-v shows where, please report it",
            file=sys.stderr,
        )
        return ExitCode.FAILURE
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
