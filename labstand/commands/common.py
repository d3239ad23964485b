"""Options and helpers several commands share."""

from __future__ import annotations

import argparse
from pathlib import Path

from sim.config import StandConfig, load_config


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
    return load_config(getattr(args, "stand", None))
