"""``labstand diagnose-check``: the diagnosis scored on campaigns whose truth is withheld."""

from __future__ import annotations

import argparse
import functools
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.commands.common import add_stand_options, load_stand
from labstand.distributed import (
    ClusterOptions,
    JobResult,
    Progress,
    add_cluster_options,
    open_client,
    run_jobs,
    say_failures,
)
from labstand.errors import CommandError, ExitCode
from labstand.targets import FILE, FOLDER
from sim.checks.choices import MASSES_KG, RECORDING_SETS, TRUTHS

if TYPE_CHECKING:  # imported where they run: `diagnose-check --help` loads no numba
    from drivers.signals import SignalSpec
    from sim.checks.check import Case, CaseSpec
    from sim.checks.check_other import PairCase
    from sim.checks.otherstand.campaign import OtherRecording
    from sim.config import StandConfig


LABEL = "labstand diagnose-check"
_WORDS = {2: "two", 3: "three"}


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand diagnose-check``."""
    parser = sub.add_parser(
        "diagnose-check",
        description="For every effect and for 'none', at both weight masses, draw a real-like "
        "stand (±25 % mismatch), a random effect magnitude and realistic noise, simulate the "
        "validation campaigns' four recordings (quick, rectangle, slack-making burst, slow; "
        "--recordings for others), diagnose them blind, and score the answers.",
    )
    add_stand_options(parser)
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--trials", type=int, default=1, help="campaigns per class and mass (1)")
    parser.add_argument(
        "--truth",
        choices=TRUTHS,
        default="same",
        help="where the truth comes from: 'same' (the candidate models' own code, default), "
        "'other' (an independently written stand with a second form of every effect, "
        "other drive signals and the validation set's noise) or 'outside' (that stand with "
        "five effects outside the catalogue, none, and none with recorder artefacts)",
    )
    parser.add_argument(
        "--triples",
        nargs="*",
        metavar="A+B+C",
        help="with --truth other: also campaigns with three effects at once (no value: the "
        "standard triples; else the given ones)",
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
    parser.add_argument(
        "--recordings",
        choices=RECORDING_SETS,
        help="the drive signals recorded per campaign, for either truth: 'moderate' "
        "(default: the validation campaigns' four), 'gentle' (three, small and slow, the "
        "fibre never slack), 'brisk' (four, quicker and larger, mostly slack) or 'paper' "
        "(the first checks' paper-like quick, medium and slow recordings, ~22 s)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON (accuracy, confusion, ...)")
    parser.add_argument("-o", "--output", type=Path, help="also write the JSON here")
    parser.add_argument(
        "--results",
        type=Path,
        metavar="DIR",
        help="write the campaigns' table and the confusion matrix here",
    )
    add_cluster_options(parser)
    parser.set_defaults(func=run, outputs={"output": FILE, "results": FOLDER})


@dataclass(frozen=True)
class CheckSetup:
    """What every campaign of a check shares (shipped to the workers with each job)."""

    stand: StandConfig
    campaign: tuple[tuple[str, SignalSpec] | OtherRecording, ...]
    truth_stand: str
    other_campaign: tuple[OtherRecording, ...]


def check_job(setup: CheckSetup, spec: CaseSpec) -> tuple[Case | PairCase, dict[str, Any]]:
    """The job: one blind campaign, scored; its diagnosis as JSON (runs on a worker)."""
    from sim.checks.check import diagnose_case

    case, diagnosis = diagnose_case(
        setup.stand, spec, setup.campaign, setup.truth_stand, setup.other_campaign
    )
    return case, diagnosis.to_dict()


def run_cases(
    setup: CheckSetup, specs: Sequence[CaseSpec], options: ClusterOptions, progress: Progress
) -> list[JobResult[tuple[Case | PairCase, dict[str, Any]]]]:
    """Every campaign on the cluster (a single one here, unless a cluster was asked for)."""
    from sim.checks.check import describe

    job = functools.partial(check_job, setup)
    keys = [s.name for s in specs]

    def tell(r: JobResult[tuple[Case | PairCase, dict[str, Any]]]) -> str:
        if r.value is None:
            return f"{r.key}: FAILED: {r.error}"
        return f"{describe(r.value[0])} on {r.worker}"

    if len(specs) <= 1 and not options.explicit:
        return run_jobs(None, job, specs, keys, progress, describe=tell)
    with open_client(options, progress.say) as (client, threads):
        return run_jobs(client, job, specs, keys, progress, threads, tell)


def _classes(args: argparse.Namespace) -> list[str]:
    """The classes asked for (CommandError, exit 2, for an unknown one)."""
    from sim.checks.check import CLASSES, OUTSIDE_CLASSES
    from sim.checks.choices import ARTEFACTS

    known = OUTSIDE_CLASSES if args.truth == "outside" else [*CLASSES, ARTEFACTS]
    if args.effects is None:
        return list(OUTSIDE_CLASSES if args.truth == "outside" else CLASSES)
    unknown = [name for name in args.effects if name not in known]
    if unknown:
        raise CommandError(
            f"--effects: unknown class {unknown[0]!r} (known: {', '.join(known)})",
            ExitCode.USAGE,
        )
    return list(args.effects)


def _pairs(args: argparse.Namespace) -> list[tuple[str, ...]]:
    """The two- and three-effect campaigns asked for (CommandError, exit 2, if malformed)."""
    from sim.checks.otherstand import OTHER_EFFECTS, OTHER_PAIRS, OTHER_TRIPLES

    chosen: list[tuple[str, ...]] = []
    for flag, given, size, standard in (
        ("--pairs", args.pairs, 2, OTHER_PAIRS),
        ("--triples", args.triples, 3, OTHER_TRIPLES),
    ):
        if given is None:
            continue
        if args.truth != "other":
            raise CommandError(f"{flag} needs --truth other", ExitCode.USAGE)
        if not given:
            chosen += list(standard)
            continue
        for text in given:
            names = tuple(text.split("+"))
            if (
                len(names) != size
                or len(set(names)) != size
                or not set(names) <= set(OTHER_EFFECTS)
            ):
                raise CommandError(
                    f"{flag}: {text!r} is not {_WORDS[size]} different effects joined by '+' "
                    f"(known: {', '.join(OTHER_EFFECTS)})",
                    ExitCode.USAGE,
                )
            chosen.append(names)
    return chosen


def _recording_set(args: argparse.Namespace) -> str:
    """The recording set asked for (CommandError, exit 2, if it cannot be)."""
    if args.recordings is None:
        return "small" if args.small else "moderate"
    if args.small:
        raise CommandError("--recordings and --small are two sets: give one", ExitCode.USAGE)
    return str(args.recordings)


def run(args: argparse.Namespace) -> int:
    """Run the check and report."""
    from labstand.campaign_table import campaign_row, write_results
    from sim.checks.check import CLASSES, SMALL_CAMPAIGN, check_cases, recording_set, score
    from sim.checks.otherstand.campaign import OTHER_SMALL

    stand = load_stand(args)
    classes = _classes(args)
    pairs = _pairs(args)
    options = ClusterOptions.from_args(args)
    recordings = _recording_set(args)
    # Both truths record the same drive signals (``--small``: each its own short pair).
    if recordings == "small":
        setup = CheckSetup(stand, SMALL_CAMPAIGN, args.truth, OTHER_SMALL)
    else:
        chosen = recording_set(recordings, stand)
        setup = CheckSetup(stand, chosen, args.truth, chosen)
    specs = check_cases(args.seed, args.trials, classes, args.mass_kg, pairs)
    progress = Progress(LABEL, len(specs), quiet=args.json)
    results = run_cases(setup, specs, options, progress)
    result = score(r.value[0] for r in results if r.value is not None)
    out = result.to_dict()
    out["seed"] = args.seed
    out["truth"] = args.truth
    out["recordings"] = recordings
    failed = [r for r in results if r.value is None]
    if failed:
        out["failed"] = [{"name": r.key, "error": r.error, "worker": r.worker} for r in failed]
    if args.results is not None:
        rows = [
            campaign_row(
                spec.name,
                spec.truth,
                None if r.value is None else r.value[1],
                r.seconds,
                r.worker,
                r.error,
            )
            for spec, r in zip(specs, results, strict=True)
        ]
        files = write_results(args.results, rows, list(dict.fromkeys([*CLASSES, *classes])))
        progress.say(f"wrote {', '.join(str(f) for f in files)}")
    code = _report(args, out)
    return ExitCode.FAILURE if say_failures(LABEL, results) else code


def _report(args: argparse.Namespace, out: dict[str, Any]) -> int:
    """Write -o, print the JSON or the summary."""
    if args.output is not None:
        args.output.write_text(json.dumps(out, indent=2))
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(
        f"{out['cases']} blind campaigns (seed {args.seed}, truth {args.truth}): top-1 accuracy "
        f"{out['accuracy']:.2f}, false alarms on none {out['false_alarm_rate']:.2f}"
    )
    if out["unidentifiable"]:
        print(
            f"  {out['unidentifiable']} campaign(s) whose true model is itself no evidence "
            f"against the fitted baseline; with none counted right there: "
            f"{out['accuracy_identifiable']:.2f}"
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
            f"{p['cases']} several-effect campaigns: pairs both named {both}, "
            f"strongest answer one of the truth {p['one_named']:.2f}"
        )
        if "triples" in p:
            print(
                f"  {p['triples']} triples: all three named {p['all_three_named']:.2f}, "
                f"at least two {p['at_least_two_named']:.2f}"
            )
    words = {
        "none_adequate": "none (and artefact-only) answered baseline_adequate",
        "outside_flagged": "outside truths answered unexplained or partly_explained",
        "outside_catalogue_named": "outside truths with a catalogue effect named",
        "outside_kind_right": "outside truths whose best signature is of the right kind",
        "catalogue_exact": "single-effect truths named exactly (no extra effect)",
    }
    for key, text in words.items():
        value = out.get("verdicts", {}).get(key)
        if value is not None:
            print(f"{text}: {value:.2f}")
    return 0
