"""``labstand campaign``: run, diagnose, plan the next test, run it, until the answer is certain.

A starting set of three tests (quick, medium, slow: the validation campaigns' drive
signals), then rounds of: diagnose every recording so far; stop if the answer is certain
(a verdict of ``baseline_adequate`` or ``explained`` with no indistinguishable rival), if
the round limit is reached, or if no admissible motion separates the rivals by at least
``labstand.planning.DECISIVE`` noise units; else plan the next test and run it. Each
test is a ``labstand run`` (at a stand without ``--yes`` it asks before each motion);
every recording, diagnosis and plan is kept in the output folder.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.errors import CommandError, ExitCode
from labstand.targets import FOLDER

if TYPE_CHECKING:
    from labstand.fitted import FittedStand

__all__ = ["register", "run"]

#: The starting set: name → ``labstand run`` signal options.
STARTING: dict[str, list[str]] = {
    "quick": ["--signal", "trapezoidal", "--amplitude-mm", "25", "--frequency-hz", "2",
              "--cycles", "4", "--ramp-fraction", "0.4"],
    "medium": ["--signal", "trapezoidal", "--amplitude-mm", "25", "--frequency-hz", "1.25",
               "--cycles", "4", "--ramp-fraction", "0.4"],
    "slow": ["--signal", "quasi-sinusoidal", "--amplitude-mm", "60", "--frequency-hz", "0.5",
             "--cycles", "3"],
}  # fmt: skip
CERTAIN_VERDICTS = ("baseline_adequate", "explained")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand campaign``."""
    parser = sub.add_parser(
        "campaign",
        description="An adaptive campaign: three starting tests, then diagnose, plan the "
        "test that best separates the rivals, run it, and again, until the answer is "
        "certain or --until rounds are done (docs/planning.md). Every recording is kept.",
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="folder for it all")
    parser.add_argument("--backend", metavar="NAME", help="sim or stand (as `labstand run`)")
    parser.add_argument(
        "--effect",
        action="append",
        default=[],
        metavar="NAME[:param=value,...]",
        help="sim: an effect the simulated stand has (repeatable)",
    )
    parser.add_argument(
        "--until",
        default="certain",
        metavar="certain|N",
        help="stop when certain (default), or after N planned tests at most",
    )
    parser.add_argument("--stand", type=Path, metavar="FILE", help="the stand file")
    parser.add_argument("--mass-kg", type=float, help="the weight on the stand, kg")
    parser.add_argument("--budget-s", type=float, default=40.0, help="each plan's search time")
    parser.add_argument("--yes", action="store_true", help="stand: start each test unasked")
    parser.set_defaults(func=run, outputs={"output": FOLDER}, find_stand=True)


def _rounds(until: str) -> int:
    """--until as a number of planned tests (certain: as many as the answer needs)."""
    if until == "certain":
        return 1_000
    try:
        rounds = int(until)
    except ValueError:
        rounds = -1
    if rounds < 0:
        raise CommandError(
            f"--until: 'certain' or a whole number ≥ 0, got {until!r}", ExitCode.USAGE
        )
    return rounds


def _say(text: str) -> None:
    print(f"labstand campaign: {text}", flush=True)


def _run(args: argparse.Namespace, name: str, signal: list[str]) -> Path:
    """One test as ``labstand run``; CommandError with its exit code if it did not end done."""
    from labstand.cli import main

    out = args.output / f"{name}.mcap"
    argv = ["run", *signal, "-o", str(out)]
    argv += [a for e in args.effect for a in ("--effect", e)]
    for option, value in (("--backend", args.backend), ("--stand", args.stand)):
        if value is not None:
            argv += [option, str(value)]
    if args.mass_kg is not None and "--plan" not in signal:
        argv += ["--mass-kg", str(args.mass_kg)]
    argv += ["--yes"] if args.yes else []
    argv += ["--force"] if args.force else []
    code = main(argv)
    if code != 0:
        known = code in {c.value for c in ExitCode}
        raise CommandError(
            f"the test {name} ended with exit code {code}; recordings kept",
            ExitCode(code) if known else ExitCode.FAILURE,
        )
    return Path(out)


def _certain(fitted: FittedStand, result: dict[str, Any]) -> tuple[bool, str]:
    """Is the answer certain, and the diagnosis in words."""
    effects = [e.name for e in fitted.effects]
    rivals = {n: r for n, r in fitted.indistinguishable.items() if r}
    words = f"{result.get('verdict')}: {' + '.join(effects) or 'nothing named'}"
    if rivals:
        words += "; indistinguishable: " + "; ".join(
            f"{n} from {', '.join(r)}" for n, r in rivals.items()
        )
    return result.get("verdict") in CERTAIN_VERDICTS and not rivals, words


def run(args: argparse.Namespace) -> int:
    """Start, then diagnose → plan → run until certain, out of rounds, or undecidable."""
    from labstand.commands.plan import diagnosed, noise_of, traces_of
    from labstand.planning import plan_motion_for
    from labstand.session.safety import SafetyLimits
    from sim.config import load_config
    from sim.envelope import SlackRule

    rounds = _rounds(args.until)
    if not (math.isfinite(args.budget_s) and args.budget_s > 0):
        raise CommandError(f"--budget-s must be > 0 s, got {args.budget_s:g}", ExitCode.USAGE)
    config = load_config(args.stand)
    args.output.mkdir(exist_ok=True)
    recordings = []
    for name, signal in STARTING.items():
        _say(f"starting test {name}")
        recordings.append(_run(args, name, signal))
    limits = SafetyLimits()
    rule = SlackRule(limits.slack_force_n, limits.slack_max_s)
    masses = [args.mass_kg] if args.mass_kg is not None else sorted(config.weights_kg.values())
    for step in range(rounds + 1):
        traces = traces_of(recordings, args.mass_kg)
        fitted, result = diagnosed(traces, config, "campaign")
        (args.output / f"diagnosis-{step}.json").write_text(json.dumps(result, indent=2))
        certain, words = _certain(fitted, result)
        _say(f"diagnosis {step} of {len(recordings)} recordings: {words}")
        if certain:
            _say("certain: done")
            return ExitCode.OK
        if step == rounds:
            _say(f"not certain after {rounds} planned test(s): stopped (--until {args.until})")
            return ExitCode.OK
        answer = plan_motion_for(
            fitted, config, masses, noise_of(traces), rule, args.budget_s, traces
        )
        _say(f"plan {step + 1}: {answer.line()}")
        if answer.plan.best is None or not answer.decisive:
            _say("no motion the stand allows settles it: stopped, the answer stays open")
            return ExitCode.OK
        plan_file = args.output / f"plan-{step + 1}.json"
        plan_file.write_text(json.dumps(answer.to_dict(), indent=2))
        recordings.append(_run(args, f"planned-{step + 1}", ["--plan", str(plan_file)]))
    return ExitCode.OK
