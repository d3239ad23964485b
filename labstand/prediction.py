"""The safety prediction before any motion: ``run`` refuses, ``simulate`` warns.

The motion is simulated with the best model of the stand the command has — the stand
file's ``final`` parameter set at the run's mass, or the fitted one of a saved diagnosis
(``--diagnosis``) — at the centre and corners of the parameters' plausible range
(``sim.envelope``). A motion whose worst case breaks the weight's travel, the fibre's safe
peak tension (the stand file's ``[safety]``) or the run's slack e-stop rule is refused
before the drive moves, unless the operator overrides the prediction.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from labstand.errors import CommandError, ExitCode

if TYPE_CHECKING:
    from drivers.signals import DriveProfile
    from labstand.fitted import FittedStand
    from labstand.session.safety import SafetyLimits
    from sim.config import StandConfig
    from sim.effects import EffectSpec
    from sim.envelope import Prediction, SlackRule

__all__ = [
    "OVERRIDE_TAG",
    "Verdict",
    "add_prediction_options",
    "check_motion",
    "fitted_from_args",
    "predict_profile",
    "warn_simulated",
]

#: The tag a recording made against the prediction carries (``labstand ls --tag``).
OVERRIDE_TAG = "prediction-overridden"
#: Where the documentation of the prediction is, for messages.
DOCS = "docs/planning.md"


def add_prediction_options(parser: argparse.ArgumentParser, override: bool) -> None:
    """--diagnosis FILE (and, for run, --override-prediction)."""
    group = parser.add_argument_group(f"safety prediction before the motion ({DOCS})")
    group.add_argument(
        "--diagnosis",
        type=Path,
        metavar="RESULT.json",
        help="predict with the model a saved `labstand diagnose --json` fitted (default: the "
        "stand file's final parameters)",
    )
    if override:
        group.add_argument(
            "--override-prediction",
            action="store_true",
            help="run a motion the prediction refuses (the override is stored in the recording)",
        )


def fitted_from_args(args: argparse.Namespace) -> FittedStand | None:
    """The model --diagnosis names, else the one a --plan was made with; exit 2 if unusable."""
    from labstand.fitted import fitted_from_dict, read_diagnosis

    path = getattr(args, "diagnosis", None)
    if path is not None:
        return read_diagnosis(path)
    plan = getattr(args, "plan", None)
    if plan is None:
        return None
    model = json.loads(plan.read_text(encoding="utf-8")).get("diagnosis")  # signal_from_plan
    return None if model is None else fitted_from_dict(model, plan)  # read it already


@dataclass(frozen=True)
class Verdict:
    """A prediction and what it says about the limits."""

    prediction: Prediction
    breaches: list[str]
    model: str
    #: The operator runs it although the prediction breaks a limit.
    overridden: bool = False

    @property
    def admissible(self) -> bool:
        """No limit broken in the worst case."""
        return not self.breaches

    @property
    def tags(self) -> tuple[str, ...]:
        """The recording's extra tags: ``OVERRIDE_TAG`` where overridden."""
        return (OVERRIDE_TAG,) if self.overridden else ()

    def override_note(self) -> str:
        """The recording's note of the override."""
        return f"prediction overridden by the operator: {self.line()}"

    def line(self) -> str:
        """The breaches (or the worst figures) and the model, in one line."""
        what = ", ".join(self.breaches) if self.breaches else self.prediction.summary()
        return f"{what}; worst of {self.prediction.runs} runs of {self.model}"


def predict_profile(
    config: StandConfig,
    profile: DriveProfile,
    mass_kg: float,
    rule: SlackRule,
    fitted: FittedStand | None,
) -> Verdict:
    """The motion's prediction with the best model available and its breaches."""
    from sim.envelope import NOMINAL_SPREAD
    from sim.prediction import predict

    stand = config.stand_params("final", mass_kg)
    _, x_m = profile.sample(config.sample_rate_hz)
    effects: tuple[EffectSpec, ...] = ()
    if fitted is None:
        spread = NOMINAL_SPREAD
        k, c, f = (
            f"±{(hi - lo) / 2:.0%}"
            for lo, hi in (spread.stiffness, spread.damping, spread.friction)
        )
        model = f"the nominal model (k {k}, c {c}, friction {f})"
    else:
        spread, effects, model = fitted.spread(), fitted.effects, fitted.describe()
    prediction = predict(stand, effects, x_m, config.sample_rate_hz, spread, rule.slack_force_n)
    return Verdict(prediction, prediction.breaches(config.envelope, rule), model)


def warn_simulated(verdict: Verdict) -> None:
    """``simulate``'s warning on stderr where ``run`` would refuse the motion."""
    if not verdict.admissible:
        print(
            f"labstand simulate: warning: `labstand run` would refuse this motion: predicted "
            f"{verdict.line()}",
            file=sys.stderr,
        )


def check_motion(
    config: StandConfig,
    profile: DriveProfile,
    mass_kg: float,
    safety: SafetyLimits,
    fitted: FittedStand | None,
    override: bool,
) -> Verdict:
    """``run``'s check: a motion predicted beyond the limits is refused (exit 3).

    ``safety``: the run's e-stop thresholds (its slack rule is predicted). With
    ``override`` the motion is not refused: a warning on stderr, and the verdict says
    overridden (the recording stores it).
    """
    from sim.envelope import SlackRule

    rule = SlackRule(safety.slack_force_n, safety.slack_max_s)
    verdict = predict_profile(config, profile, mass_kg, rule, fitted)
    if verdict.admissible:
        return verdict
    if not override:
        raise CommandError(
            f"predicted {verdict.line()}; nothing moved (--override-prediction runs it anyway)",
            ExitCode.REFUSED,
        )
    print(f"labstand: warning: prediction overridden: {verdict.line()}", file=sys.stderr)
    return replace(verdict, overridden=True)
