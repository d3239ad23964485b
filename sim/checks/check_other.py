"""The check's other truth: campaigns of ``sim.checks.otherstand`` as traces, and two-effect scores.

Kept apart from ``check`` so the other truth stays an add-on to it (see ``check``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sim.checks.otherstand.campaign import OtherRecording, make_other_campaign
from sim.checks.otherstand.gauges import Realism
from sim.config import StandConfig
from sim.identify.heldout import Outputs
from sim.identify.report import Diagnosis
from sim.identify.traces import Trace, make_trace

__all__ = ["PairCase", "named_effects", "other_campaign_traces", "pairs_summary"]


@dataclass(frozen=True)
class PairCase:
    """One blind diagnosis of a campaign with two (or three) effects at once."""

    truth: tuple[str, ...]
    mass_kg: float
    answer: str
    #: The diagnosis's accepted effects, or None while it reports only one.
    answers: tuple[str, ...] | None
    truth_params: dict[str, float]
    seconds: float

    @property
    def both_named(self) -> bool:
        """Both true effects among the accepted ones (False without an ``effects`` list)."""
        return self.answers is not None and set(self.truth) <= set(self.answers)

    @property
    def named_count(self) -> int:
        """How many of the true effects are among the accepted ones."""
        return len(set(self.truth) & set(self.answers or ()))

    @property
    def one_named(self) -> bool:
        """The strongest answer is one of the two."""
        return self.answer in self.truth


def pairs_summary(cases: Sequence[PairCase]) -> dict[str, Any]:
    """Two-effect campaigns: the share with both named, and with one named.

    Both named needs the diagnosis's ``effects`` list; until it has one,
    ``effects_reported`` is false and only ``one_named`` (the strongest answer is one of
    the pair) counts.
    """
    n = len(cases)
    triples = [c for c in cases if len(c.truth) == 3]
    pairs = [c for c in cases if len(c.truth) == 2]
    return {
        "cases": n,
        "both_named": sum(c.both_named for c in pairs) / len(pairs) if pairs else 0.0,
        **(
            {
                "triples": len(triples),
                "all_three_named": sum(c.both_named for c in triples) / len(triples),
                "at_least_two_named": sum(c.named_count >= 2 for c in triples) / len(triples),
            }
            if triples
            else {}
        ),
        "one_named": sum(c.one_named for c in cases) / n if n else 0.0,
        "effects_reported": all(c.answers is not None for c in cases),
        "details": [
            {**c.__dict__, "both_named": c.both_named, "one_named": c.one_named} for c in cases
        ],
    }


def other_campaign_traces(
    stand: StandConfig,
    effects: Sequence[str],
    mass_kg: float,
    rng: np.random.Generator,
    recordings: Sequence[OtherRecording],
    artefacts: bool = False,
) -> tuple[list[Trace], list[Outputs], dict[str, float]]:
    """Traces, noise-free outputs and parameters (``effect.param``) of a campaign.

    The campaign runs on the other stand with the named effects (none, or several; the
    out-of-catalogue ones too); ``artefacts``: its recorder adds drawn artefacts (lost
    samples, jitter, a hum harmonic, spikes: ``Realism.with_artefacts``).
    """
    nominal = stand.stand_params("final", mass_kg)
    realism = Realism.with_artefacts(rng) if artefacts else None
    camp = make_other_campaign(
        nominal, effects, rng, recordings, stand.sample_rate_hz, realism=realism
    )
    traces = [make_trace(name, t, x, u, f, mass_kg) for name, t, x, u, f in camp.recordings]
    oracle = [Outputs(u, f) for u, f in zip(camp.truth_u, camp.truth_f, strict=True)]
    params = {f"{e}.{k}": v for e, values in camp.effects.items() for k, v in values.items()}
    return traces, oracle, params


def named_effects(diagnosis: Diagnosis) -> tuple[str, ...]:
    """The names of the effects a diagnosis named, strongest first."""
    return tuple(e.effect for e in diagnosis.effects)
