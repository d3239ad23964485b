"""Options and helpers several commands share."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sim.config import StandConfig


def add_stand_options(parser: argparse.ArgumentParser, params: bool = False) -> None:
    """--stand FILE (and --params NAME)."""
    parser.add_argument(
        "--stand",
        type=Path,
        metavar="FILE",
        help="stand configuration (default: $LABSTAND_STAND, else ./labstand.toml, else the "
        "paper's stand)",
    )
    parser.set_defaults(find_stand=True)  # labstand.cli fills --stand in (labstand.stands)
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


def config_with_mass(config: StandConfig, mass_kg: float) -> dict[str, Any]:
    """The stand configuration whose default weight is the mass on the stand.

    This is how a recording stores the weight it was made with (``run``, ``import``):
    later commands read it as the stored stand's default weight.
    """
    raw = config.to_dict()
    weights = raw["weights_kg"]
    name = next((n for n, m in weights.items() if m == mass_kg), None)
    if name is None:
        name = next(
            f"run{i or ''}" for i in range(len(weights) + 1) if f"run{i or ''}" not in weights
        )
        weights[name] = mass_kg
    raw["weight"]["default"] = name
    from sim.config import config_from_dict  # scipy: only when a command runs

    config_from_dict(raw, config.source)  # still valid
    return raw


def add_metadata_options(parser: argparse.ArgumentParser) -> None:
    """--operator, --sample and --tag (repeatable): stored in the recording, listed by ls."""
    group = parser.add_argument_group("run metadata (stored in the recording; labstand ls)")
    group.add_argument("--operator", default="", metavar="NAME", help="who runs it")
    group.add_argument("--sample", default="", metavar="ID", help="the sample (fibre) id")
    group.add_argument(
        "--tag", action="append", default=[], metavar="TAG", help="a free label (repeatable)"
    )


def metadata_options(args: argparse.Namespace, tags: tuple[str, ...] = ()) -> dict[str, Any]:
    """The keywords of ``make_metadata`` / ``with_changes`` the options above give.

    ``tags``: more tags the command adds (a run against its safety prediction).
    """
    all_tags = (*args.tag, *tags)
    out: dict[str, Any] = {"tags": tuple(all_tags)} if all_tags else {}
    out.update({k: getattr(args, k) for k in ("operator", "sample") if getattr(args, k)})
    return out
