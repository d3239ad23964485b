"""Campaign manifests: read whole before anything runs; a malformed one is refused (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest

from labstand.campaigns import load_manifest
from labstand.cli import main

A = "[campaign.a]\nrecordings = ['r.csv']\n"


def test_paths_are_relative_to_the_manifest(tmp_path: Path) -> None:
    (tmp_path / "lab").mkdir()
    manifest = tmp_path / "lab" / "m.toml"
    manifest.write_text(
        '[campaign.light]\nrecordings = ["a.mcap", "../b.h5"]\nmass_kg = 3.096\n'
        'stand = "stand.toml"\ntruth = "none"\n\n'
        '[campaign.heavy]\nrecordings = ["/data/c.csv"]\nmass_kg = 8\n'
    )
    light, heavy = load_manifest(manifest)
    assert light.name == "light" and light.mass_kg == 3.096 and light.truth == "none"
    assert light.recordings == (tmp_path / "lab" / "a.mcap", tmp_path / "b.h5")
    assert light.stand == tmp_path / "lab" / "stand.toml"
    assert heavy.recordings == (Path("/data/c.csv"),) and heavy.mass_kg == 8.0
    assert heavy.stand is None and heavy.truth is None


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[campaign.a\n", "m.toml: not TOML: "),
        ("title = 'x'\n", "m.toml: no [campaign.NAME] tables"),
        ("[campaign.a]\nrecordings = []\nmass_kg = 3\n",
         "[campaign.a]: recordings must be a non-empty list of paths"),
        (f"{A}mass_kg = 'heavy'\n", "[campaign.a]: mass_kg must be a number > 0, got 'heavy'"),
        (f"{A}mass_kg = -3\n", "mass_kg must be a number > 0, got -3"),
        (f"{A}mass_kg = 3\nmass = 4\n",
         "[campaign.a]: unknown key(s) mass (known: mass_kg, recordings, stand, truth)"),
        (f"{A}mass_kg = 3\nstand = 1\n", "[campaign.a]: stand must be a string"),
    ],
)  # fmt: skip
def test_a_malformed_manifest_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, message: str
) -> None:
    manifest = tmp_path / "m.toml"
    manifest.write_text(text)
    assert main(["diagnose", "--campaigns", str(manifest)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and str(manifest) in err


def test_campaigns_refuse_what_the_manifest_says_and_a_missing_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "none.toml"
    assert main(["diagnose", "--campaigns", str(missing)]) == 2
    assert f"cannot read the manifest: no such file: {missing}" in capsys.readouterr().err
    assert main(["diagnose", "x.csv", "--campaigns", str(missing)]) == 2
    assert "--campaigns takes the recordings" in capsys.readouterr().err
    assert main(["diagnose"]) == 2
    assert "no recordings given (or --campaigns FILE)" in capsys.readouterr().err
    assert main(["diagnose", "--campaigns", str(missing), "--workers", "0"]) == 2
