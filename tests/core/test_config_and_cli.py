"""The stand file and the offline commands, as a user meets them."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from labstand.cli import main
from sim.config import ConfigError, default_config, load_config


def test_defaults_are_the_papers_stand() -> None:
    c = default_config()
    assert c.weights_kg == {"light": 3.096, "heavy": 8.131}
    assert c.default_mass_kg == 8.131
    start, final = c.parameter_sets["starting"], c.parameter_sets["final"]
    assert (start.stiffness_n_m, start.damping_n_s_m, start.friction) == (94e3, 46.9, "none")
    assert (final.stiffness_n_m, final.damping_n_s_m, final.friction) == (34e3, 27.5, "default")
    assert c.drive.amplitude_max_m == pytest.approx(0.090)
    assert c.sample_rate_hz == 2000.0
    p = c.stand_params("final")
    assert p.projection == pytest.approx(0.8992, abs=1e-4)
    assert p.drive_span_m == pytest.approx(1.093, abs=1e-3)


def test_a_stand_file_overlays_the_defaults(tmp_path: Path) -> None:
    f = tmp_path / "stand.toml"
    f.write_text(
        "[weights_kg]\nheavy = 9.0\n[params.mine]\nstiffness_n_m = 50e3\n"
        'damping_n_s_m = 30.0\nfriction = "default"\n'
    )
    c = load_config(f)
    assert c.default_mass_kg == 9.0
    assert c.stand_params("mine").stiffness_n_m == 50e3
    assert c.stand_params("final").stiffness_n_m == 34e3  # untouched keys keep their default


BAD_FILES = [
    ("[weights_kg]\nheavy = -8.131\n", "[weights_kg] heavy: must be > 0, got -8.131"),
    ("[drive]\namplitude_max_mm = 120\n", "[drive] amplitude_max_mm: must be ≤ 90, got 120"),
    ("[drive]\nspeed_max = 1.0\n", "[drive] speed_max: unknown key; expected one of"),
    (
        "[geometry]\nincline_deg = 'steep'\n",
        "[geometry] incline_deg: must be a number, got str 'steep'",
    ),
    (
        "[params.final]\nstiffness_n_m = true\n",
        "[params.final] stiffness_n_m: must be a number, got bool",
    ),
    (
        "[friction.default]\nspeed_m_s = [0.001, 0.1, 0.05, 0.2, 0.3, 1.0]\n",
        "[friction.default] speed_m_s: must be strictly increasing",
    ),
    ("[friction.default]\nmu = [0.1, 0.2]\n", "[friction.default] mu: needs 6 values"),
    (
        '[params.final]\nfriction = "sticky"\n',
        "[params.final] friction: names no [friction.*] table",
    ),
    ("[pulley]\ninertia = 1\n", "unknown table [pulley]"),
    ("[drive\n", "not valid TOML"),
    ('[weight]\ndefault = "medium"\n', "[weight] default: names no weight"),
    ("[geometry]\nlateral_offset_m = 0.7\n", "[geometry] lateral_offset_m: must be shorter"),
]


@pytest.mark.parametrize(("content", "message"), BAD_FILES)
def test_bad_stand_files_get_one_line_naming_file_and_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str, message: str
) -> None:
    f = tmp_path / "stand.toml"
    f.write_text(content)
    with pytest.raises(ConfigError) as err:
        load_config(f)
    assert str(err.value).startswith(f"{f}: ")
    assert message in str(err.value)
    # Through the CLI: the same message, one line, exit code 2, no traceback.
    code = main(["model", "modes", "--stand", str(f)])
    captured = capsys.readouterr()
    assert code == 2
    assert captured.err.count("\n") == 1 and message in captured.err
    assert "Traceback" not in captured.err


def test_missing_stand_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["model", "modes", "--stand", str(tmp_path / "nope.toml")]) == 2
    assert "nope.toml: no such stand file" in capsys.readouterr().err


def test_simulate_a_situation_writes_the_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run.csv"
    assert (
        main(["simulate", "--situation", "11", "--params", "final", "-o", str(out), "--json"]) == 0
    )
    summary = json.loads(capsys.readouterr().out)
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert out.read_text().splitlines()[0] == "t_s,x_mm,u_mm,F_N"
    assert data.shape == (summary["samples"], 4)
    assert np.allclose(np.diff(data[:, 0]), 0.0005)
    assert data[:, 1].max() == pytest.approx(25.0, rel=1e-6)  # situation 11: A = 25 mm
    assert summary["slack_fraction"] > 0 and summary["mass_kg"] == 8.131
    assert data[:, 3].min() >= 0


def test_simulate_any_signal_with_a_mass(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = [
        "simulate",
        "--signal",
        "trapezoidal",
        "--amplitude-mm",
        "60",
        "--frequency-hz",
        "0.25",
        "--cycles",
        "2",
        "--mass-kg",
        "8.131",
        "--json",
        "--plot",
        str(tmp_path / "p.png"),
    ]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["signal"]["amplitude_mm"] == 60 and summary["signal"]["cycles"] == 2
    assert (tmp_path / "p.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (
            ["--signal", "trapezoidal", "--amplitude-mm", "95", "--frequency-hz", "1"],
            3,
            "refused: amplitude 95 mm exceeds the drive limit 90 mm",
        ),
        (
            ["--signal", "quasi-sinusoidal", "--amplitude-mm", "80", "--frequency-hz", "3"],
            3,
            "exceeds the drive limit 10 m/s²",
        ),
        (["--signal", "trapezoidal", "--frequency-hz", "1"], 2, "--signal needs --amplitude-mm"),
        ([], 2, "give --situation NAME or --signal SHAPE"),
        (["--situation", "11", "--params", "middle"], 2, "no parameter set 'middle'"),
        (["--situation", "11", "-o", "x.parquet"], 2, "unknown output format '.parquet'"),
        (["--situation", "11", "--mass-kg", "-3"], 2, "mass must be > 0 kg"),
    ],
)
def test_simulate_refusals(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    fixed = [str(tmp_path / a) if a.endswith(".parquet") else a for a in args]
    assert main(["simulate", *fixed]) == code
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "x.parquet").exists()


def test_model_modes_json_lands_near_the_papers_frequencies(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["model", "modes", "--params", "starting", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mass_kg"] == [3.096, 8.131]
    assert out["modes_hz"][0] == pytest.approx(25.0, abs=0.2)
    assert out["modes_hz"][1] == pytest.approx(15.25, abs=0.2)
    assert main(["model", "modes", "--params", "final", "--mass-kg", "8.131", "--json"]) == 0
    (f,) = json.loads(capsys.readouterr().out)["modes_hz"]
    assert f == pytest.approx(15.39 * (34 / 94) ** 0.5, rel=1e-3)


def test_console_script_help_for_every_command() -> None:
    exe = Path(sys.executable).with_name("labstand")
    top = subprocess.run([exe, "--help"], capture_output=True, text=True, check=True)
    commands = ["simulate", "model"]
    for name in commands:
        assert name in top.stdout
        res = subprocess.run([exe, name, "--help"], capture_output=True, text=True, check=True)
        assert "usage: labstand" in res.stdout
