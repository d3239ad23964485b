"""What a check's campaigns add up to: verdicts, interval coverage, per-recording trends."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from sim.checks.choices import ARTEFACTS
from sim.checks.otherstand.outside import OUTSIDE_EFFECTS, SIGNATURE_KIND
from sim.effects import EFFECTS
from sim.identify.report import Diagnosis

if TYPE_CHECKING:
    from sim.checks.check import Case


def verdict_summary(cases: Sequence[Case]) -> dict[str, Any]:
    """What the verdicts say, by kind of truth (each share over its campaigns; None: none).

    ``none``: none and artefact-only campaigns answered ``baseline_adequate``;
    ``outside``: out-of-catalogue truths answered ``unexplained`` or
    ``partly_explained``, with a catalogue effect named, with the best signature of the
    truth's kind; ``catalogue``: single-effect truths whose named set is exactly the truth.
    """

    def share(selected: Sequence[Case], test: Callable[[Case], bool]) -> float | None:
        return sum(map(test, selected)) / len(selected) if selected else None

    nones = [c for c in cases if c.truth in ("none", ARTEFACTS)]
    outside = [c for c in cases if c.truth in OUTSIDE_EFFECTS]
    catalogue = [c for c in cases if c.truth in EFFECTS]
    return {
        "none_adequate": share(nones, lambda c: c.verdict == "baseline_adequate"),
        "outside_flagged": share(
            outside, lambda c: c.verdict in ("unexplained", "partly_explained")
        ),
        "outside_catalogue_named": share(outside, lambda c: bool(c.named)),
        "outside_kind_right": share(
            outside,
            lambda c: bool(c.signature_kinds) and c.signature_kinds[0] == SIGNATURE_KIND[c.truth],
        ),
        "catalogue_exact": share(catalogue, lambda c: c.named == (c.truth,)),
    }


def coverage_summary(cases: Sequence[Case]) -> dict[str, dict[str, float]]:
    """Per parameter (the baseline's and ``effect.param``): share of intervals holding the truth.

    Counted where the truth is known and the diagnosis reported an interval for it: the
    baseline's multipliers on same-form truths, an effect's parameters where the effect
    was named. ``{name: {"share": s, "intervals": n}}``, and ``all`` over every parameter.
    """
    counts: dict[str, list[bool]] = {}
    for c in cases:
        for name, held in c.covered.items():
            counts.setdefault(name, []).append(held)
    out = {n: {"share": sum(v) / len(v), "intervals": len(v)} for n, v in sorted(counts.items())}
    every = [h for v in counts.values() for h in v]
    if every:
        out["all"] = {"share": sum(every) / len(every), "intervals": len(every)}
    return out


#: The effect whose fingerprint the per-recording fits are checked for (issue 28).
BRANCH = "fibre_viscoelastic"
#: A ``Case.trends`` key: the baseline alone's fibre law stiffer at quicker strain rates.
DYNAMIC = "dynamic_stiffness"


def trend_summary(cases: Sequence[Case]) -> dict[str, dict[str, float]]:
    """Per truth: how often the baseline alone's stiffness was found to rise with the rate.

    ``stiffness_with_rate``: fitted per recording, its stiffness was flagged moving with
    the drive rate; ``stiffness_with_strain_rate``: the fibre's law read off the
    recordings is stiffer the quicker the fibre is strained (``dynamic_stiffness``);
    ``flagged``: either; ``points_to_branch``: either, or any per-recording parameter
    moved in a way that points to a relaxation branch (a stiffness rising or a damping
    falling with the rate, or with the stroke).
    """
    by_truth: dict[str, list[tuple[bool, bool, bool]]] = {}
    for c in cases:
        with_rate = "drive_rate_hz" in c.trends.get("stiffness_scale", "").split("+")
        with_strain_rate = DYNAMIC in c.trends
        branch = any(BRANCH in text for text in c.points_to.values())
        by_truth.setdefault(c.truth, []).append((with_rate, with_strain_rate, branch))
    return {
        t: {
            "stiffness_with_rate": sum(a for a, _, _ in v) / len(v),
            "stiffness_with_strain_rate": sum(b for _, b, _ in v) / len(v),
            "flagged": sum(a or b for a, b, _ in v) / len(v),
            "points_to_branch": sum(p for _, _, p in v) / len(v),
            "campaigns": len(v),
        }
        for t, v in by_truth.items()
    }


def baseline_trends(d: Diagnosis) -> tuple[dict[str, str], dict[str, str]]:
    """The baseline alone's per-recording trends: what each scale moved with, what it points to.

    Covariates are joined by ``+`` where the recordings cannot tell them apart.
    """
    trends = {
        k: "+".join([v["moves_with"], *v.get("also_with", [])])
        for k, v in d.baseline_consistency.items()
        if v["moves_with"]
    }
    pointers = {k: v["points_to"] for k, v in d.baseline_consistency.items() if v["points_to"]}
    dynamic = d.dynamic_stiffness.get("baseline_alone") or {}
    if dynamic.get("rises_with_rate"):
        trends[DYNAMIC] = "strain_rate_hz"
        pointers[DYNAMIC] = dynamic["points_to"]
    return trends, pointers


def covered_truth(d: Diagnosis, effect: str, truth: dict[str, float]) -> dict[str, bool]:
    """Whether each interval the diagnosis gives holds the true value (where it is known).

    ``truth``: a same-form campaign's parameters (``make_campaign``): the baseline's
    multipliers and the true ``effect``'s own parameters. Keys: the baseline's names and
    ``effect.param``.
    """
    held = {}
    for name, (lo, hi) in d.baseline_intervals.items():
        if name in truth:
            held[name] = bool(lo <= truth[name] <= hi)
    for a in d.effects:
        for name, (lo, hi) in a.intervals.items():
            if a.effect == effect and name in truth and lo < hi:  # a held count has none
                held[f"{effect}.{name}"] = bool(lo <= truth[name] <= hi)
    return held
