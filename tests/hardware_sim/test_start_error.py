"""A simulated stand that cannot start says why in its own words (its stderr)."""

from __future__ import annotations

import pytest

from sim.hardware.process import StandProcess, StandStartError


def test_the_childs_own_message_reaches_the_caller() -> None:
    sim = StandProcess(["--effect", "no_such_effect"])
    with pytest.raises(StandStartError) as info:
        sim.start()
    message = str(info.value)
    assert message.startswith("the simulated stand did not start: ")
    assert "no_such_effect" in message and "closed file" not in message
    assert "\n" not in message and "labstand: error:" not in message
    assert sim.process is not None and sim.process.returncode == 2
