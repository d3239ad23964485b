"""Options and helpers several commands share."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sim.config import StandConfig


def add_stand_options(parser: argparse.ArgumentParser, params: bool = False) -> None:
    """--stand FILE (and --params NAME)."""
    parser.add_argument(
        "--stand", type=Path, metavar="FILE", help="stand configuration (default: the paper's)"
    )
    if params:
        parser.add_argument(
            "--params",
            default="final",
            metavar="NAME",
            help="parameter set of the stand file: starting, final, ... (default: final)",
        )


def load_stand(args: argparse.Namespace) -> StandConfig:
    """The stand configuration the user chose, validated."""
    from sim.config import load_config  # scipy: only when a command runs

    return load_config(getattr(args, "stand", None))
