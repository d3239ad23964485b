"""``labstand completion SHELL``: a shell completion script (shtab), printed on stdout."""

from __future__ import annotations

import argparse
from pathlib import Path

SHELLS = ("bash", "zsh", "tcsh")
#: Options that name a folder rather than a file (completed as folders).
FOLDER_OPTIONS = {"report", "results"}


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand completion``."""
    parser = sub.add_parser(
        "completion",
        description="Print a completion script for SHELL: commands, options and file "
        'names complete with TAB. Bash: eval "$(labstand completion bash)" in ~/.bashrc '
        "(or save it in /etc/bash_completion.d/labstand); zsh: save it as _labstand on "
        "$fpath.",
    )
    parser.add_argument("shell", choices=SHELLS, help="the shell")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Build the whole parser (every command's options) and print its script."""
    import shtab

    from labstand.cli import build_parser

    parser = build_parser(None)  # every command's module: only here, not at each TAB
    for action in _actions(parser):
        if action.type is Path:
            folder = action.dest in FOLDER_OPTIONS
            action.complete = shtab.DIRECTORY if folder else shtab.FILE  # type: ignore[attr-defined]
    print(shtab.complete(parser, shell=args.shell))
    return 0


def _actions(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """Every action of the parser and its sub-parsers."""
    out = []
    for action in parser._actions:  # argparse keeps them here; stable since Python 3.2
        out.append(action)
        if isinstance(action, argparse._SubParsersAction):
            for child in dict.fromkeys(action.choices.values()):
                out += _actions(child)
    return out
