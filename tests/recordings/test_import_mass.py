"""The weight given at import is stored with the recording and used by later commands."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from labstand.cli import main
from labstand.commands.diagnose import _mass_of
from recordings import open_recording
from sim.config import load_config


@pytest.fixture(scope="module")
def light_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("light") / "light.csv"
    assert main(["simulate", "--situation", "11", "--mass-kg", "3.096", "-o", str(out)]) == 0
    return out


def _replay(capsys: pytest.CaptureFixture[str], *args: str) -> dict:
    capsys.readouterr()
    assert main(["replay", *args, "--json"]) == 0
    out: dict = json.loads(capsys.readouterr().out)
    return out


def test_imported_light_run_replays_with_its_stored_mass(light_csv: Path, tmp_path: Path, capsys):
    rec = tmp_path / "light.mcap"
    assert main(["import", str(light_csv), "--mass-kg", "3.096", "-o", str(rec), "--force"]) == 0
    assert "weight 3.096 kg (--mass-kg), stored with it" in capsys.readouterr().out
    out = _replay(capsys, str(rec))
    assert out["mass_kg"] == 3.096 and out["mass_source"] == "stored in the recording"
    assert out["channels"]["F"]["R"] > 0.9999
    # an explicit option still wins, and says so
    heavy = _replay(capsys, str(rec), "--mass-kg", "8.131")
    assert heavy["mass_source"] == "--mass-kg" and heavy["channels"]["F"]["R"] < 0.5
    stand = tmp_path / "stand.toml"
    stand.write_text('[weight]\ndefault = "heavy"\n', encoding="utf-8")
    by_file = _replay(capsys, str(rec), "--stand", str(stand))
    assert by_file["mass_kg"] == 8.131
    assert by_file["mass_source"] == f"default weight of {stand}"
    # the text output names the mass and its source
    assert main(["replay", str(rec)]) == 0
    assert "m = 3.096 kg (stored in the recording)" in capsys.readouterr().out
    assert main(["table1", str(rec), "--json"]) == 0
    row = json.loads(capsys.readouterr().out)[0]
    assert row["mass_kg"] == 3.096 and row["second"]["R_F_dyn"] > 0.9999


def test_import_without_mass_uses_the_stands_default_and_says_so(
    light_csv: Path, tmp_path: Path, capsys
):
    rec = tmp_path / "default.h5"
    assert main(["import", str(light_csv), "-o", str(rec), "--force"]) == 0
    assert "weight 8.131 kg (the paper stand's default weight; give --mass-kg" in (
        capsys.readouterr().out
    )
    out = _replay(capsys, str(rec))
    assert out["mass_kg"] == 8.131 and out["channels"]["F"]["R"] < 0.5


def test_import_stand_file_parameters_are_stored(light_csv: Path, tmp_path: Path, capsys):
    stand, rec = tmp_path / "stand.toml", tmp_path / "light.mcap"
    stand.write_text(
        '[weight]\ndefault = "light"\n[params.final]\nstiffness_n_m = 50000.0\n', encoding="utf-8"
    )
    assert main(["import", str(light_csv), "--stand", str(stand), "-o", str(rec), "--force"]) == 0
    assert f"weight 3.096 kg (default weight of {stand})" in capsys.readouterr().out
    stored = open_recording(rec).metadata.stand_config
    assert stored["params"]["final"]["stiffness_n_m"] == 50000.0
    assert _replay(capsys, str(rec))["mass_kg"] == 3.096
    assert main(["import", str(light_csv), "--mass-kg", "0", "-o", str(rec), "--force"]) == 2
    assert "--mass-kg must be > 0 kg, got 0" in capsys.readouterr().err


def test_diagnose_takes_the_mass_as_replay_does(light_csv: Path, tmp_path: Path, capsys):
    rec = tmp_path / "light.mcap"
    assert main(["import", str(light_csv), "--mass-kg", "3.096", "-o", str(rec), "--force"]) == 0
    stored = open_recording(rec).metadata.stand_config
    assert _mass_of(rec, stored, None, None) == (3.096, "stored in the recording")
    assert _mass_of(rec, stored, 5.0, None) == (5.0, "--mass-kg")
    paper = load_config(None)
    assert _mass_of(rec, stored, None, paper) == (8.131, f"default weight of {paper.source}")
    assert _mass_of(rec, {"weights_kg": "x"}, None, None)[0] == 8.131


def test_tdms_import_stores_the_mass_too(tmp_path: Path, capsys):
    from .test_import import MAP, _tdms

    src, rec = tmp_path / "legacy.tdms", tmp_path / "legacy.h5"
    _tdms(src)
    assert main(["import", str(src), *MAP, "--mass-kg", "3.096", "-o", str(rec), "--force"]) == 0
    assert "weight 3.096 kg (--mass-kg)" in capsys.readouterr().out
    stored = open_recording(rec).metadata.stand_config
    assert stored["weights_kg"][stored["weight"]["default"]] == 3.096
