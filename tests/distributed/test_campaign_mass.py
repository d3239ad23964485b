"""A campaign without ``mass_kg`` takes the weight stored in each recording, as a single
``labstand diagnose`` does."""

from __future__ import annotations

from pathlib import Path

import pytest

import labstand.campaigns as campaigns
from labstand.campaigns import diagnose_campaign, load_manifest
from labstand.cli import main
from sim.identify import Trace


def test_the_stored_weight_is_each_recordings(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    for name, mass in (("light.mcap", "3.096"), ("heavy.h5", "8.131")):
        argv = ["simulate", "--situation", "11", "--mass-kg", mass, "-o", str(tmp_path / name)]
        assert main(argv) == 0
    manifest = tmp_path / "m.toml"
    manifest.write_text('[campaign.a]\nrecordings = ["light.mcap", "heavy.h5"]\n')
    (campaign,) = load_manifest(manifest)
    assert campaign.mass_kg is None
    seen: list[Trace] = []

    class Result:  # the fit itself is the diagnosis' business; here: which mass it gets
        def to_dict(self) -> dict[str, object]:
            return {"effect": "none"}

    def fake_diagnose(traces: list[Trace], nominal: object) -> Result:
        seen.extend(traces)
        return Result()

    monkeypatch.setattr(campaigns, "diagnose", fake_diagnose)
    out = diagnose_campaign(campaign)
    assert [t.mass_kg for t in seen] == [3.096, 8.131]
    assert out["mass_kg"] == {
        str(tmp_path / "light.mcap"): 3.096,
        str(tmp_path / "heavy.h5"): 8.131,
    }
