"""``labstand campaign`` on the simulated stand: the starting tests, a diagnosis, the stop."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from labstand.errors import ExitCode
from recordings import open_recording
from tests.run.conftest import Outcome, labstand_process


def test_a_campaign_stops_where_its_diagnosis_says_with_everything_kept(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    # as a process, as a user starts it
    # a 1 ms force skew (the diagnosis often cannot tell it from a gauge low-pass,
    # docs/planning.md); --until 0 allows no planned test
    out = tmp_path / "campaign"
    args = ["--backend", "sim", "--effect", "channel_time_skew", "--until", "0", "-o", out]
    result = labstand_process("campaign", *args, timeout_s=900.0)
    assert result.code == 0, result.err
    lines = [x for x in result.out.splitlines() if x.startswith("labstand campaign: ")]
    assert lines[:3] == [
        f"labstand campaign: starting test {n}" for n in ("quick", "medium", "slow")
    ]
    assert lines[3].startswith("labstand campaign: diagnosis 0 of 3 recordings: ")
    for name in ("quick", "medium", "slow"):
        assert open_recording(out / f"{name}.mcap").metadata.effects[0].name == "channel_time_skew"
    # the stop follows from the diagnosis kept beside the recordings
    diagnosis = json.loads((out / "diagnosis-0.json").read_text())
    rivals = [r for e in diagnosis["effects"] for r in e["indistinguishable_from"]]
    certain = diagnosis["verdict"] in ("baseline_adequate", "explained") and not rivals
    for e in diagnosis["effects"]:
        assert e["effect"] in lines[3]
        if e["indistinguishable_from"]:
            assert f"{e['effect']} from {', '.join(e['indistinguishable_from'])}" in lines[3]
    assert ("indistinguishable: " in lines[3]) == bool(rivals)
    assert lines[4] == (
        "labstand campaign: certain: done"
        if certain
        else "labstand campaign: not certain after 0 planned test(s): stopped (--until 0)"
    )
    assert len(lines) == 5

    again = labstand("campaign", *args)  # the folder exists: nothing run, nothing lost
    assert again.code == ExitCode.USAGE and "exists; nothing written" in again.err
    bad = labstand("campaign", "--until", "soon", "-o", tmp_path / "other")
    assert bad.code == ExitCode.USAGE and "--until: 'certain' or a whole number" in bad.err
    assert not (tmp_path / "other").exists()
