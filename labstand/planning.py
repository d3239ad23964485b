"""``labstand plan``'s parts: the rivals a diagnosis leaves, the search, the answer.

The rivals (``rivals_of``): each named effect against each candidate the recordings could
not tell from it (``indistinguishable_from``; the rival in its place among the named
ones); failing those, the first against the runner-up of the ranking and against the
baseline alone; with nothing named, each of the ranking's ``MAX_UNNAMED`` best against
the baseline. Each rival is the diagnosis' fitted baseline plus its effect at the
parameters its own refit found (the ranking's ``params``).

Second, the plan narrows the widest interval (``widest_interval``: the named effects'
parameter whose 95 % interval is widest against its value): among motions that tell every
pair apart, the one that tells most of it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.errors import CommandError, ExitCode

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from drivers.signals import SignalSpec
    from labstand.fitted import FittedStand
    from sim.config import StandConfig
    from sim.envelope import SlackRule
    from sim.identify.traces import Trace
    from sim.planner import Narrowing, Noise, Plan, Rival, Setting

__all__ = [
    "PLAN_OPTIONS",
    "PlanAnswer",
    "narrowing_for",
    "plan_motion_for",
    "rivals_of",
    "setting_for",
    "signal_from_plan",
    "widest_interval",
]

BASELINE = "none"
#: A separation below this many noise units counts as hardly telling the rivals apart.
DECISIVE = 1.0  # sim.planner.DECISIVE; here without importing the simulation
#: At most this many pairs are separated when an effect is named (each costs one batch
#: of segment runs per motion, each way round).
MAX_PAIRS = 3
#: With nothing named, this many of the ranking's best candidates each against the
#: baseline: the question is which of them the stand has, if any.
MAX_UNNAMED = 5


def rivals_of(fitted: FittedStand) -> tuple[list[Rival], list[tuple[str, str]]]:
    """The rival models and the pairs to separate; CommandError (2) if there are none."""
    from sim.effects import EffectSpec
    from sim.planner import Rival

    named = list(fitted.effects)
    ranked = [name for name in fitted.rivals if name not in {e.name for e in named}]
    pairs: list[tuple[str, str]] = []
    #: Which named effect (by its place) each rival would stand in for.
    replaces: dict[str, int] = {}
    for place, effect in enumerate(named):  # the first effect's rivals first
        for other in fitted.indistinguishable.get(effect.name, []):
            if other in fitted.rivals and other not in replaces:
                replaces[other] = place
                pairs.append((effect.name, other))
    if named and not pairs:
        pairs = [(named[0].name, other) for other in [*ranked[:1], BASELINE]]
    elif ranked and not named:
        pairs = [(name, BASELINE) for name in ranked[:MAX_UNNAMED]]
    if not pairs:
        raise CommandError(
            f"{fitted.source}: no rival explanations to separate (nothing named, no ranked "
            "candidate with fitted parameters)",
            ExitCode.USAGE,
        )
    pairs = pairs[: MAX_PAIRS if named else MAX_UNNAMED]
    rest = tuple(named[1:])
    models: dict[str, Rival] = {}
    for name in {n for pair in pairs for n in pair}:
        if name == BASELINE:
            models[name] = Rival(name, rest)
        elif name in {e.name for e in named}:
            models[name] = Rival(name, tuple(named))
        else:  # in place of the named effect it could not be told from (the first if none)
            place = replaces.get(name, 0)
            stand_in = EffectSpec(name, fitted.rivals[name])
            models[name] = Rival(name, (*named[:place], stand_in, *named[place + 1 :]))
    return [models[n] for n in sorted(models)], pairs


def widest_interval(
    fitted: FittedStand, fitted_param: Callable[[str], bool] = lambda _key: True
) -> tuple[str, float, tuple[float, float]] | None:
    """The named effects' parameter whose interval is widest against its value, or None.

    ``("effect.param", value, (low, high))``, from the diagnosis' ``effects[].intervals``,
    among the keys ``fitted_param`` accepts; parameters held at a level (an interval of
    no width) are not candidates.
    """
    best: tuple[float, tuple[str, float, tuple[float, float]]] | None = None
    for item in fitted.raw.get("effects") or []:
        if not isinstance(item, dict):
            continue
        params, intervals = item.get("params") or {}, item.get("intervals") or {}
        for name, pair in intervals.items():
            value = params.get(name)
            key = f"{item.get('effect')}.{name}"
            if not isinstance(value, (int, float)) or not isinstance(pair, list) or len(pair) != 2:
                continue
            if not fitted_param(key):
                continue
            low, high = float(min(pair)), float(max(pair))
            width = (high - low) / max(abs(float(value)), 1e-12)
            if high > low and (best is None or width > best[0]):
                best = (width, (key, float(value), (low, high)))
    return best[1] if best is not None else None


def narrowing_for(
    fitted: FittedStand, config: StandConfig, noise: Noise, traces: Sequence[Trace] = ()
) -> Narrowing | None:
    """The interval the plan narrows second, with what the recordings hold about it."""
    from sim.discrimination import effect_steps, parameter_information
    from sim.planner import Narrowing
    from sim.prediction import centre_stand

    refitted = {key for step in effect_steps(fitted.effects) for key in step}
    widest = widest_interval(fitted, refitted.__contains__)
    if widest is None or not fitted.effects:
        return None
    key, value, interval = widest
    held = 0.0
    for tr in traces:
        stand = centre_stand(config.stand_params("final", tr.mass_kg), fitted.spread())
        held += parameter_information(tr, stand, fitted.effects, key, noise.u_m, noise.force_n)
    return Narrowing(fitted.effects[0].name, key, value, interval, held if traces else None)


@dataclass(frozen=True)
class PlanAnswer:
    """The plan with what it was searched against, for the line and the JSON."""

    plan: Plan
    fitted: FittedStand
    config: StandConfig
    rule: SlackRule
    noise: Noise
    budget_s: float
    narrowing: Narrowing | None = None

    @property
    def decisive(self) -> bool:
        """The plan's worst-separated pair differs by at least ``DECISIVE`` noise units."""
        return self.plan.best is not None and self.plan.expected_separation >= DECISIVE

    def line(self) -> str:
        """Why, in one line."""
        plan = self.plan
        if plan.best is None or plan.prediction is None:
            return (
                f"no admissible motion among the {plan.searched} searched: none is predicted "
                "within the limits and free of slack"
            )
        (a, b), sep = min(plan.separations.items(), key=lambda kv: kv[1])
        worst = plan.prediction.worst
        weak = "" if self.decisive else f" only (below {DECISIVE:g}: hardly told apart)"
        told = sum(v >= DECISIVE for v in plan.separations.values())
        pairs = len(plan.separations)
        what = (
            f"separates {a} from {b} by {sep:.1f} noise units{weak}"
            if pairs == 1
            else f"tells {told} of {pairs} rival pairs apart; the worst, {a} from {b}, by "
            f"{sep:.1f} noise units{weak}"
        )
        return (
            f"{plan.best.describe()} {what}{self._narrows_words()}; "
            f"predicted slack {worst.slack_share:.0%}, peak {worst.peak_tension_n:.0f} N, "
            f"weight travel {worst.weight_travel_m * 1e3:.0f} mm"
        )

    def _narrows_words(self) -> str:
        narrow = self.narrowing
        predicted = narrow.predicted(self.plan.information) if narrow is not None else None
        if narrow is None or predicted is None:
            return ""
        low, high = narrow.interval
        return (
            f", and narrows {narrow.key} from [{low:.4g}, {high:.4g}] to "
            f"[{predicted[0]:.4g}, {predicted[1]:.4g}] (predicted)"
        )

    def _narrows_dict(self) -> dict[str, Any] | None:
        narrow = self.narrowing
        if narrow is None:
            return None
        predicted = narrow.predicted(self.plan.information)
        return {
            "parameter": narrow.key,
            "value": narrow.value,
            "interval": list(narrow.interval),
            "information": self.plan.information,
            "held_by_recordings": narrow.held,
            "predicted_interval": list(predicted) if predicted is not None else None,
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON: the signal (as ``run`` takes it), separates, narrows, and predicted."""
        plan = self.plan
        out: dict[str, Any] = {
            "why": self.line(),
            "signal": None,
            "separates": [
                {"rivals": [a, b], "separation": sep} for (a, b), sep in plan.separations.items()
            ],
            "expected_separation": plan.expected_separation,
            "narrows": self._narrows_dict(),
            "decisive": self.decisive,
            "predicted": None,
            "noise": {"u_m": self.noise.u_m, "force_n": self.noise.force_n},
            "searched": plan.searched,
            "admissible": plan.admissible,
            "complete": plan.complete,
            "budget_s": self.budget_s,
            # the model the plan was predicted with: `run --plan` predicts with it too
            "diagnosis": {
                key: self.fitted.raw.get(key)
                for key in ("baseline_fit", "baseline_intervals", "effects", "verdict")
            },
        }
        if plan.best is not None and plan.prediction is not None:
            out["signal"] = {**plan.best.spec.to_dict(), "mass_kg": plan.best.mass_kg}
            worst = plan.prediction.worst
            out["predicted"] = {
                "peak_tension_n": worst.peak_tension_n,
                "slack_share": worst.slack_share,
                "longest_slack_s": worst.longest_slack_s,
                "weight_travel_mm": worst.weight_travel_m * 1e3,
                "margins": plan.prediction.margins(self.config.envelope, self.rule),
                "runs": plan.prediction.runs,
            }
        return out


def setting_for(
    fitted: FittedStand,
    config: StandConfig,
    noise: Noise,
    rule: SlackRule,
    narrowing: Narrowing | None = None,
) -> Setting:
    """What the search needs of a diagnosis and a stand (its rivals, model, limits)."""
    from sim.planner import Setting

    rivals, pairs = rivals_of(fitted)
    if narrowing is not None and narrowing.rival not in {r.name for r in rivals}:
        narrowing = None
    return Setting(
        nominal=config.stand_params("final"),
        spread=fitted.spread(),
        named=fitted.effects,
        rivals=tuple(rivals),
        pairs=tuple(pairs),
        noise=noise,
        envelope=config.envelope,
        rule=rule,
        limits=config.drive,
        rate_hz=config.sample_rate_hz,
        narrow=narrowing,
    )


def plan_motion_for(
    fitted: FittedStand,
    config: StandConfig,
    masses_kg: list[float],
    noise: Noise,
    rule: SlackRule,
    budget_s: float,
    traces: Sequence[Trace] = (),
) -> PlanAnswer:
    """Search the stand's motions for the one that best separates the diagnosis' rivals.

    ``traces``: the recordings behind the diagnosis, for how far the plan narrows the
    widest interval (without them it is still narrowed, but by how much is not said).
    """
    from sim.planner import motion_grid, search

    narrowing = narrowing_for(fitted, config, noise, traces)
    setting = setting_for(fitted, config, noise, rule, narrowing)
    plan = search(setting, motion_grid(config.drive, masses_kg), budget_s)
    return PlanAnswer(plan, fitted, config, rule, noise, budget_s, setting.narrow)


#: The signal options ``run --plan`` takes from the plan (the command line may not add).
PLAN_OPTIONS = (
    "situation", "signal", "amplitude_mm", "frequency_hz", "cycles", "ramp_fraction",
    "dwell_start_s", "dwell_end_s", "mass_kg",
)  # fmt: skip


def signal_from_plan(path: Path, given: list[str]) -> tuple[SignalSpec, float]:
    """The motion and mass of a plan (``labstand plan -o``); exit 2 if it is not one.

    ``given``: signal options also on the command line: refused, the plan is run as it is.
    """
    from drivers.signals import Shape, SignalSpec

    if given:
        raise CommandError(
            f"--plan runs the plan's motion as it is: no {', '.join(given)} beside it",
            ExitCode.USAGE,
        )
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CommandError(f"no such file: {path}", ExitCode.USAGE) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise CommandError(f"{path}: not a plan: {err}", ExitCode.USAGE) from None
    signal = data.get("signal") if isinstance(data, dict) else None
    if not isinstance(signal, dict):
        raise CommandError(f"{path}: not a plan: no signal (an empty plan?)", ExitCode.USAGE)
    try:
        spec = SignalSpec(
            shape=Shape(signal["shape"]),
            amplitude_m=float(signal["amplitude_mm"]) / 1e3,
            frequency_hz=float(signal["frequency_hz"]),
            cycles=int(signal["cycles"]),
            ramp_fraction=float(signal["ramp_fraction"]),
            dwell_start_s=float(signal["dwell_start_s"]),
            dwell_end_s=float(signal["dwell_end_s"]),
        )
        mass = float(signal["mass_kg"])
    except (KeyError, TypeError, ValueError) as err:
        raise CommandError(f"{path}: not a plan's signal: {err!r}", ExitCode.USAGE) from None
    if signal["cycles"] != spec.cycles:
        raise CommandError(f"{path}: cycles must be a whole number", ExitCode.USAGE)
    return spec, mass
