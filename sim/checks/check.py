"""The check on withheld effects: campaigns with known truth, diagnosed blind, scored.

For every effect and for ``none``, at each weight mass, a campaign is drawn: a "real"
stand (stiffness, damping and friction scale off nominal by up to ±25 %), the effect at
a random magnitude within its plausible range, realistic gauge and drive encoder noise.
Its recordings (``campaign``, or a named ``recording_set``) are simulated with that
truth; the diagnosis sees only the recordings and the nominal stand. ``truth_stand``:
``"same"`` draws the truth from the candidate models themselves; ``"other"`` from
``sim.checks.otherstand``, an independently written stand with a second form of every
effect; ``"outside"`` that stand with effects outside the catalogue. ``pairs`` and
``triples`` add campaigns with several effects at once (scores: ``summaries``).
"""

from __future__ import annotations

import dataclasses
import logging
import time
import zlib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivers.signals import Shape, SignalSpec, plan_motion
from sim.checks import summaries
from sim.checks.check_other import PairCase, named_effects, other_campaign_traces, pairs_summary
from sim.checks.choices import ARTEFACTS, MASSES_KG, RECORDING_SETS, TRUTHS
from sim.checks.otherstand.campaign import OTHER_FULL, OTHER_SETS, OtherRecording
from sim.checks.otherstand.outside import OUTSIDE_EFFECTS
from sim.config import StandConfig
from sim.effects import EFFECTS, EffectSpec
from sim.effects.realism import MeasurementNoise, NoiseSpec, draw_real_stand
from sim.identify.decide import compare
from sim.identify.fitting import Candidate, simulate_values
from sim.identify.heldout import Outputs, heldout_error
from sim.identify.pipeline import diagnose
from sim.identify.report import Diagnosis
from sim.identify.shooting import dial_slope
from sim.identify.traces import Trace, make_trace
from sim.model import Model
from sim.params import StandParams

log = logging.getLogger(__name__)

CLASSES = ["none", *EFFECTS]
#: The outside truth's classes: none, none with artefacts, and the five outside effects.
OUTSIDE_CLASSES = ["none", ARTEFACTS, *OUTSIDE_EFFECTS]
#: Drive encoder noise on x, m rms (the model is driven by the *measured* x).
DRIVE_NOISE_M = 1e-6

#: (name, signal): quick, medium and slow motions (paper-like; ~22 s in all).
FULL_CAMPAIGN = (
    ("quick", SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=5, ramp_fraction=0.4)),
    ("medium", SignalSpec(Shape.TRAPEZOIDAL, 0.025, 1.25, cycles=4, ramp_fraction=0.4)),
    ("slow", SignalSpec(Shape.QUASI_SINUSOIDAL, 0.060, 0.5, cycles=3)),
)
#: A shorter campaign for the test suite (~9 s).
SMALL_CAMPAIGN = (
    (
        "quick",
        SignalSpec(Shape.TRAPEZOIDAL, 0.025, 2.0, cycles=4, ramp_fraction=0.4, dwell_end_s=0.5),
    ),
    ("slow", SignalSpec(Shape.QUASI_SINUSOIDAL, 0.060, 0.5, cycles=2, dwell_end_s=0.5)),
)


#: A campaign's recordings: (name, signal) under the stand's drive limits, or the other
#: stand's recordings (signal and limits each; ``sim.checks.otherstand.campaign.OTHER_SETS``).
CampaignSpec = Sequence[tuple[str, SignalSpec] | OtherRecording]


def recording_set(name: str, stand: StandConfig) -> tuple[OtherRecording, ...]:
    """A named set of drive signals, for either truth (ValueError if unknown)."""
    if name == "paper":
        return tuple(OtherRecording(n, signal, stand.drive) for n, signal in FULL_CAMPAIGN)
    if name in OTHER_SETS:
        return OTHER_SETS[name]
    raise ValueError(f"unknown recording set {name!r}; known: {', '.join(RECORDING_SETS)}")


@dataclass(frozen=True)
class Case:
    """One blind diagnosis and its truth."""

    truth: str
    mass_kg: float
    answer: str
    truth_params: dict[str, float]
    shrink: float
    oracle_shrink: float
    seconds: float
    #: Whether the true model itself is evidence against the fitted baseline (the
    #: decision's test, as a single test); None where it cannot be judged alike (the
    #: other stand's truth is open loop). False: ``none`` is a right answer too.
    identifiable: bool | None = None
    #: The diagnosis's verdict, every effect it named, and the kinds of the signatures
    #: that describe its remainder (best first).
    verdict: str = ""
    named: tuple[str, ...] = ()
    signature_kinds: tuple[str, ...] = ()
    #: Per true parameter the diagnosis gave an interval for: whether it holds the truth.
    covered: dict[str, bool] = field(default_factory=dict)
    #: Per baseline parameter fitted per recording that moved: what it moved with
    #: (covariates joined by ``+`` where the recordings cannot tell them apart).
    trends: dict[str, str] = field(default_factory=dict)
    #: Per baseline parameter fitted per recording whose spread points somewhere: to what.
    points_to: dict[str, str] = field(default_factory=dict)

    @property
    def right(self) -> bool:
        """The truth named, or ``none`` for a truth the recordings cannot show."""
        return self.answer == self.truth or (self.identifiable is False and self.answer == "none")


@dataclass
class CheckResult:
    """Scores of a check run (see to_dict for the JSON keys)."""

    cases: list[Case] = field(default_factory=list)
    pair_cases: list[PairCase] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """accuracy, false_alarm_rate, confusion, median_shrink, verdicts, details, ..."""
        truths = list(dict.fromkeys(c.truth for c in self.cases))
        labels = list(dict.fromkeys([*CLASSES, *truths]))
        confusion = {t: dict.fromkeys(labels, 0) for t in truths}
        for c in self.cases:
            confusion[c.truth][c.answer] += 1
        n = len(self.cases)
        correct = [c for c in self.cases if c.answer == c.truth]
        nones = [c for c in self.cases if c.truth in ("none", ARTEFACTS)]
        effects_ok = [c for c in correct if c.truth != "none"]
        return {
            "cases": n,
            "accuracy": len(correct) / n if n else 0.0,
            # Also right: ``none`` where the true model is no evidence either (``Case``).
            "accuracy_identifiable": sum(c.right for c in self.cases) / n if n else 0.0,
            "unidentifiable": sum(c.identifiable is False for c in self.cases),
            "false_alarm_rate": (
                sum(c.answer != "none" for c in nones) / len(nones) if nones else 0.0
            ),
            "confusion": confusion,
            "median_shrink": float(np.median([c.shrink for c in effects_ok]))
            if effects_ok
            else 0.0,
            "oracle_median_shrink": (
                float(np.median([c.oracle_shrink for c in effects_ok])) if effects_ok else 0.0
            ),
            "median_seconds": float(np.median([c.seconds for c in self.cases])) if n else 0.0,
            "verdicts": summaries.verdict_summary(self.cases),
            "coverage": summaries.coverage_summary(self.cases),
            "trends": summaries.trend_summary(self.cases),
            "details": [c.__dict__ for c in self.cases],
            **({"pairs": pairs_summary(self.pair_cases)} if self.pair_cases else {}),
        }


def make_campaign(
    stand: StandConfig,
    truth: str,
    mass_kg: float,
    rng: np.random.Generator,
    campaign: CampaignSpec = FULL_CAMPAIGN,
    open_loop_oracle: bool = False,
    truth_stand: str = "same",
    other_campaign: Sequence[OtherRecording] = OTHER_FULL,
) -> tuple[list[Trace], list[Outputs], dict[str, float]]:
    """Recordings of a drawn "real" stand with the effect ``truth`` (or none).

    Returns the traces (what the diagnosis sees), the true model's outputs (the oracle:
    judged by multiple shooting like every candidate, or with ``open_loop_oracle`` the
    true noise-free channels), and the true effect parameters. With
    ``truth_stand="other"`` the recordings are ``other_campaign`` on the other stand,
    ``truth`` may name two effects joined by ``+``, the parameters are keyed
    ``effect.param``, and the oracle is the other stand's noise-free channels (its
    equations are not the candidates', so no candidate can be judged as the truth).
    """
    if truth_stand in ("other", "outside"):
        names = [] if truth in ("none", ARTEFACTS) else truth.split("+")
        return other_campaign_traces(
            stand, names, mass_kg, rng, other_campaign, artefacts=truth == ARTEFACTS
        )
    if truth_stand != "same":
        raise ValueError(f"truth_stand must be one of {', '.join(TRUTHS)}, got {truth_stand!r}")
    nominal = stand.stand_params("final", mass_kg)
    real = draw_real_stand(nominal, rng)
    effects: list[EffectSpec] = []
    # The true baseline multipliers too: what the diagnosis's intervals must hold.
    params: dict[str, float] = true_scales(nominal, real)
    if truth != "none":
        spec = EffectSpec(truth, EFFECTS[truth].draw(rng))
        effects = [spec]
        params.update(spec.resolved())
    noise = NoiseSpec.draw(rng)
    traces, oracle = [], []
    for item in campaign:
        name, signal, limits = (
            (item.name, item.signal, item.limits)
            if isinstance(item, OtherRecording)
            else (item[0], item[1], stand.drive)
        )
        t, x = plan_motion(signal, limits).sample(stand.sample_rate_hz)
        run = Model(real, effects).run(x, stand.sample_rate_hz)
        gauges = MeasurementNoise(noise, stand.sample_rate_hz, rng)
        u_rec, f_rec = gauges.apply(run.u_m, run.force_n)
        x_rec = np.round((x + rng.normal(0.0, DRIVE_NOISE_M, x.size)) / 1e-7) * 1e-7
        trace = make_trace(name, t, x_rec, u_rec, f_rec, mass_kg)
        traces.append(trace)
        # The trace's u counts from its rest value; the model's rest is u = 0 (plus any
        # dial gauge offset, which the rest value removes).
        oracle.append(Outputs(run.true_u_m - run.true_u_m[0], run.true_force_n))
    if not open_loop_oracle:
        # As ``diagnose`` sees them: the campaign's dial gauge scale on every trace.
        slope = dial_slope(traces)
        judged = [dataclasses.replace(tr, dial_slope=slope) for tr in traces]
        oracle = [_oracle(tr, nominal, real, effects) for tr in judged]
    return traces, oracle, params


def true_scales(nominal: StandParams, real: StandParams) -> dict[str, float]:
    """The drawn stand's stiffness, damping and friction as the fit's multipliers."""
    return {
        "stiffness_scale": real.stiffness_n_m / nominal.stiffness_n_m,
        "damping_scale": real.damping_n_s_m / nominal.damping_n_s_m,
        "friction_scale": real.friction_scale / nominal.friction_scale,
    }


def _oracle(
    trace: Trace, nominal: StandParams, real: StandParams, effects: Sequence[EffectSpec]
) -> Outputs:
    """The true model (the drawn stand, the true effect) judged as every candidate is.

    Simulated by multiple shooting from the recording's measured states, like the
    candidates, so "how far the true model shrinks the gap" compares like with like (an
    open-loop run of the truth knows no restart error at all).
    """
    values = true_scales(nominal, real)
    for spec in effects:
        values.update({f"{spec.name}.{k}": v for k, v in spec.resolved().items()})
    if "dial_gauge_calibration.offset_m" in values:  # a trace counts u from its rest value
        values["dial_gauge_calibration.offset_m"] = 0.0
    candidate = Candidate.build(*(spec.name for spec in effects))
    u, f = simulate_values(candidate, [values], trace, nominal)
    return Outputs(u[0], f[0])


@dataclass(frozen=True)
class CaseSpec:
    """One campaign of a check: its truth (an effect, ``none``, or two joined by ``+``).

    Its random draws come from ``rng()``, seeded by the check's seed and what the campaign
    is (truth, mass, trial), never by what ran before it or where it runs: a campaign's
    answer is the same in a serial loop, on one worker or on a hundred.
    """

    truth: str
    mass_kg: float
    trial: int = 0
    seed: int = 0

    @property
    def name(self) -> str:
        """A unique, readable key: ``truth@massKG#trial``."""
        return f"{self.truth}@{self.mass_kg:g}kg#{self.trial}"

    @property
    def pair(self) -> bool:
        """Two effects at once."""
        return "+" in self.truth

    def rng(self) -> np.random.Generator:
        """The campaign's own generator (see the class docstring)."""
        key = [self.seed, self.trial, zlib.crc32(self.truth.encode()), round(self.mass_kg * 1e3)]
        return np.random.default_rng(key)


def check_cases(
    seed: int = 0,
    trials: int = 1,
    classes: Sequence[str] = CLASSES,
    masses: Sequence[float] = MASSES_KG,
    pairs: Sequence[tuple[str, ...]] = (),
) -> list[CaseSpec]:
    """The campaigns of a check: trials × masses × (classes, then pairs)."""
    return [
        CaseSpec(truth, float(mass), trial, seed)
        for trial in range(trials)
        for mass in masses
        for truth in [*classes, *("+".join(p) for p in pairs)]
    ]


def diagnose_case(
    stand: StandConfig,
    spec: CaseSpec,
    campaign: CampaignSpec = FULL_CAMPAIGN,
    truth_stand: str = "same",
    other_campaign: Sequence[OtherRecording] = OTHER_FULL,
) -> tuple[Case | PairCase, Diagnosis]:
    """Generate one campaign, diagnose it blind, and score the answer.

    Returns the scored case (a ``PairCase`` for two effects) and the full diagnosis.
    """
    if spec.pair and truth_stand == "same":
        raise ValueError("several effects at once need the other truth stand")
    traces, oracle, params = make_campaign(
        stand, spec.truth, spec.mass_kg, spec.rng(), campaign,
        truth_stand=truth_stand, other_campaign=other_campaign,
    )  # fmt: skip
    started = time.perf_counter()
    d = diagnose(traces, stand.stand_params("final", spec.mass_kg))
    seconds = time.perf_counter() - started
    if spec.pair:
        truth = tuple(spec.truth.split("+"))
        return PairCase(truth, spec.mass_kg, d.effect, named_effects(d), params, seconds), d
    e_before = d.heldout_error_before
    shrink = (e_before - d.heldout_error_after) / e_before if e_before > 0 else 0.0
    e_true = heldout_error(traces, oracle)
    oracle_shrink = (e_before - e_true) / e_before if e_before > 0 else 0.0
    identifiable = None
    if truth_stand == "same" and spec.truth != "none":
        # The truth judged like a candidate against the fitted baseline: if even it is
        # no evidence of an effect, ``none`` is what the recordings show.
        identifiable = compare(traces, d.outputs_before, oracle).accepted(tests=1)
    kinds = tuple(s.kind for s in d.remainder.signature if s.passes) if d.remainder else ()
    trends, pointers = summaries.baseline_trends(d)
    case = Case(
        spec.truth, spec.mass_kg, d.effect, params, shrink, oracle_shrink, seconds, identifiable,
        d.verdict, named_effects(d), kinds,
        summaries.covered_truth(d, spec.truth, params) if truth_stand == "same" else {}, trends,
        pointers,
    )  # fmt: skip
    return case, d


def describe(case: Case | PairCase) -> str:
    """One progress line for a scored case."""
    if isinstance(case, PairCase):
        mark = "both" if case.both_named else "one" if case.one_named else "WRONG"
        return (
            f"m={case.mass_kg:g} kg truth {'+'.join(case.truth)}: answer {case.answer} "
            f"(effects {case.answers}; {mark}, {case.seconds:.0f} s)"
        )
    mark = "ok" if case.answer == case.truth else "WRONG"
    if case.truth in OUTSIDE_EFFECTS or case.truth == ARTEFACTS:
        mark = "outside" if case.truth in OUTSIDE_EFFECTS else "artefacts"
    kinds = f", signature {'/'.join(case.signature_kinds)}" if case.signature_kinds else ""
    return (
        f"m={case.mass_kg:g} kg truth {case.truth}: answer {case.answer}, {case.verdict}"
        f"{kinds} ({mark}, {case.seconds:.0f} s)"
    )


def score(cases: Iterable[Case | PairCase]) -> CheckResult:
    """The check's result from its scored cases (in any order; kept in the given one)."""
    result = CheckResult()
    for case in cases:
        if isinstance(case, PairCase):
            result.pair_cases.append(case)
        else:
            result.cases.append(case)
    return result


def run_check(
    stand: StandConfig,
    seed: int = 0,
    trials: int = 1,
    classes: Sequence[str] = CLASSES,
    masses: Sequence[float] = MASSES_KG,
    campaign: CampaignSpec = FULL_CAMPAIGN,
    progress: Callable[[str], None] | None = None,
    truth_stand: str = "same",
    other_campaign: Sequence[OtherRecording] = OTHER_FULL,
    pairs: Sequence[tuple[str, ...]] = (),
) -> CheckResult:
    """Diagnose trials × classes × masses blind campaigns one after another and score them.

    ``truth_stand`` and ``other_campaign``: see ``make_campaign``. ``pairs`` (other truth
    only): two-effect campaigns, each at every mass, scored apart (``CheckResult.pair_cases``).
    The same campaigns run in parallel elsewhere (``labstand.distributed``) through
    ``check_cases``, ``diagnose_case`` and ``score``.
    """
    if pairs and truth_stand == "same":
        raise ValueError("several effects at once need the other truth stand")
    say = progress or (lambda _m: None)
    specs = check_cases(seed, trials, classes, masses, pairs)
    cases: list[Case | PairCase] = []
    for k, spec in enumerate(specs, 1):
        case, _ = diagnose_case(stand, spec, campaign, truth_stand, other_campaign)
        cases.append(case)
        say(f"[{k}/{len(specs)}] {describe(case)}")
    return score(cases)
