"""``labstand diagnose-check``: the diagnosis scored on campaigns whose truth is withheld."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from labstand.commands.common import add_stand_options, load_stand
from labstand.errors import CommandError, ExitCode

# Literal copies of sim.identify.check's TRUTHS and MASSES_KG, which imports numba: the
# parser is built without it (a test checks that they agree).
TRUTHS = ("same", "other")
MASSES_KG = (3.096, 8.131)


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand diagnose-check``."""
    parser = sub.add_parser(
        "diagnose-check",
        description="For every effect and for 'none', at both weight masses, draw a real-like "
        "stand (±25 % mismatch), a random effect magnitude and realistic noise, simulate a "
        "quick, a medium and a slow recording, diagnose them blind, and score the answers.",
    )
    add_stand_options(parser)
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--trials", type=int, default=1, help="campaigns per class and mass (1)")
    parser.add_argument(
        "--truth",
        choices=TRUTHS,
        default="same",
        help="where the truth comes from: 'same' (the candidate models' own code, default) "
        "or 'other' (an independently written stand with a second form of every effect, "
        "other drive signals and the validation set's noise)",
    )
    parser.add_argument(
        "--pairs",
        nargs="*",
        metavar="A+B",
        help="with --truth other: also campaigns with two effects at once (no value: the "
        "standard pairs; else the given ones, e.g. stick_slip_friction+channel_time_skew)",
    )
    parser.add_argument(
        "--effects",
        nargs="*",
        metavar="NAME",
        help="classes to check (default: all nine effects and none; none given: no "
        "single-effect campaigns, only --pairs)",
    )
    parser.add_argument(
        "--mass-kg",
        type=float,
        nargs="+",
        default=list(MASSES_KG),
        help="weight masses (default: 3.096 8.131)",
    )
    parser.add_argument(
        "--small",
        action="store_true",
        help="short campaigns (two recordings, ~9 s): quicker, less sure",
    )
    parser.add_argument("--json", action="store_true", help="print JSON (accuracy, confusion, ...)")
    parser.add_argument("-o", "--output", type=Path, help="also write the JSON here")
    parser.set_defaults(func=run)


def _classes(args: argparse.Namespace) -> list[str]:
    """The classes asked for (all by default; CommandError, exit 2, for an unknown one)."""
    from sim.identify.check import CLASSES

    if args.effects is None:
        return list(CLASSES)
    unknown = [name for name in args.effects if name not in CLASSES]
    if unknown:
        raise CommandError(
            f"--effects: unknown class {unknown[0]!r} (known: {', '.join(CLASSES)})",
            ExitCode.USAGE,
        )
    return list(args.effects)


def _pairs(args: argparse.Namespace) -> list[tuple[str, str]]:
    """The two-effect campaigns asked for (CommandError, exit 2, if malformed)."""
    from sim.otherstand import OTHER_EFFECTS, OTHER_PAIRS

    if args.pairs is None:
        return []
    if args.truth != "other":
        raise CommandError("--pairs needs --truth other", ExitCode.USAGE)
    if not args.pairs:
        return list(OTHER_PAIRS)
    pairs = []
    for text in args.pairs:
        names = text.split("+")
        if len(names) != 2 or names[0] == names[1] or not set(names) <= set(OTHER_EFFECTS):
            raise CommandError(
                f"--pairs: {text!r} is not two different effects joined by '+' "
                f"(known: {', '.join(OTHER_EFFECTS)})",
                ExitCode.USAGE,
            )
        pairs.append((names[0], names[1]))
    return pairs


def run(args: argparse.Namespace) -> int:
    """Run the check and report."""
    from sim.identify.check import FULL_CAMPAIGN, SMALL_CAMPAIGN, run_check
    from sim.otherstand.campaign import OTHER_FULL, OTHER_SMALL

    stand = load_stand(args)
    classes = _classes(args)
    pairs = _pairs(args)

    def progress(message: str) -> None:
        print(f"labstand diagnose-check: {message}", file=sys.stderr, flush=True)

    result = run_check(
        stand, seed=args.seed, trials=args.trials, classes=classes, masses=args.mass_kg,
        campaign=SMALL_CAMPAIGN if args.small else FULL_CAMPAIGN, progress=progress,
        truth_stand=args.truth, other_campaign=OTHER_SMALL if args.small else OTHER_FULL,
        pairs=pairs,
    )  # fmt: skip
    out = result.to_dict()
    out["seed"] = args.seed
    out["truth"] = args.truth
    if args.output is not None:
        args.output.write_text(json.dumps(out, indent=2))
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(
        f"{out['cases']} blind campaigns (seed {args.seed}, truth {args.truth}): top-1 accuracy "
        f"{out['accuracy']:.2f}, false alarms on none {out['false_alarm_rate']:.2f}"
    )
    print(
        f"median NRMSE shrink (correct answers) {out['median_shrink']:.2f}, "
        f"the true model's {out['oracle_median_shrink']:.2f}"
    )
    labels = list(out["confusion"])
    short = [name[:6] for name in labels]
    print("confusion (rows: truth, columns: answer):")
    print(" " * 28 + " ".join(f"{s:>6s}" for s in short))
    for truth in labels:
        row = out["confusion"][truth]
        print(f"  {truth:26s}" + " ".join(f"{row[a]:6d}" for a in labels))
    if "pairs" in out:
        p = out["pairs"]
        both = f"{p['both_named']:.2f}" if p["effects_reported"] else "n/a (no effects list yet)"
        print(
            f"{p['cases']} two-effect campaigns: both named {both}, "
            f"strongest answer one of the pair {p['one_named']:.2f}"
        )
    return 0
