"""A check campaign's draws depend on what it is, not on what runs beside or before it."""

from __future__ import annotations

import numpy as np

from sim.checks.check import CaseSpec, check_cases


def test_a_campaign_draws_the_same_whatever_else_the_check_holds() -> None:
    full = check_cases(seed=4, trials=2, classes=["none", "stick_slip_friction"],
                       masses=[3.096, 8.131], pairs=[("a", "b")])  # fmt: skip
    alone = check_cases(seed=4, trials=2, classes=["stick_slip_friction"], masses=[8.131])
    assert [s.name for s in full][:3] == [
        "none@3.096kg#0", "stick_slip_friction@3.096kg#0", "a+b@3.096kg#0",
    ]  # fmt: skip
    by_name = {s.name: s for s in full}
    for spec in alone:
        assert np.array_equal(spec.rng().random(4), by_name[spec.name].rng().random(4))
    draws = {s.name: tuple(s.rng().random(2)) for s in full}
    assert len(set(draws.values())) == len(full)  # every campaign its own stream
    other_seed = CaseSpec("none", 3.096, 0, seed=5)
    assert not np.array_equal(other_seed.rng().random(2), full[0].rng().random(2))
