"""``labstand run`` predicts a motion before the drive moves, and refuses one beyond the limits.

The refusals run as real processes (``python -m labstand run``) against the real
simulated stand: once with ``--backend sim`` (the stand is never even started), once at
a stand that stays up (``--backend stand``), whose drive an independent Modbus client
reads afterwards: no profile written, never enabled.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from drivers import unidrive_registers as pr
from labstand.errors import ExitCode
from labstand.prediction import OVERRIDE_TAG
from recordings import open_recording
from sim.hardware.process import StandProcess
from tests.run.conftest import SHORT, Outcome, labstand_process
from tests.run.test_run_after_run import Observer

#: The README's example: 60 mm trapezoid at 2 Hz with the heavy weight (slack 67.9 %,
#: the weight 373 mm up its guide in the model).
README = [
    "--signal", "trapezoidal", "--amplitude-mm", "60", "--frequency-hz", "2", "--cycles", "5",
    "--mass-kg", "8.131",
]  # fmt: skip


@pytest.fixture
def stand_up(tmp_path: Path) -> Iterator[tuple[Path, Observer]]:
    """A simulated stand that stays up, and a stand file whose [devices] name it."""
    with StandProcess() as sim:
        ep = sim.endpoints
        stand = tmp_path / "stand.toml"
        stand.write_text(f'[devices]\ndrive = "{ep["modbus"]}"\ngauges = "{ep["gauges"]}"\n')
        observer = Observer(int(ep["modbus"].rsplit(":", 1)[1]))
        try:
            yield stand, observer
        finally:
            observer.client.close()


def test_the_readme_example_is_refused_before_the_simulated_stand_starts(tmp_path: Path) -> None:
    out = tmp_path / "readme.mcap"
    result = labstand_process("run", "--backend", "sim", *README, "-o", out)
    assert result.code == ExitCode.REFUSED, result.err
    line = result.last_error_line
    assert line.startswith("labstand: refused: predicted weight travel "), line
    assert "(limit 120 mm)" in line and "peak tension" in line and "(limit 0.25 s)" in line
    assert "nothing moved (--override-prediction runs it anyway)" in line
    assert "simulated stand (pid" not in result.out  # no stand, no drive, nothing moved
    assert not out.exists()


def test_at_a_stand_the_refused_drive_is_never_enabled(
    stand_up: tuple[Path, Observer], tmp_path: Path
) -> None:
    stand, drive = stand_up
    before = drive.read(pr.DRIVE_CLOCK)
    out = tmp_path / "readme.mcap"
    result = labstand_process("run", "--stand", stand, "--yes", *README, "-o", out)
    assert result.code == ExitCode.REFUSED, result.err
    assert "predicted weight travel" in result.last_error_line
    assert not out.exists()
    # the drive's own registers: no profile written, output never enabled, at home
    assert drive.read(pr.PROFILE_AMPLITUDE) == 0
    assert not drive.read(pr.STATUS_WORD) & pr.StatusBit.ACTIVE.mask
    assert drive.read(pr.POSITION) == 0
    assert drive.read(pr.DRIVE_CLOCK) > before  # the stand was up and answering all along

    # the same stand runs an admissible motion: the observer would have seen one
    ok = tmp_path / "ok.mcap"
    brief = ["--signal", "trapezoidal", "--amplitude-mm", "10", "--frequency-hz", "2"]
    result = labstand_process("run", "--stand", stand, "--yes", *brief, "--cycles", "1", "-o", ok)
    assert result.code == 0, result.err
    assert drive.read(pr.PROFILE_AMPLITUDE) == 10_000  # µm
    assert OVERRIDE_TAG not in open_recording(ok).metadata.tags


def test_an_admissible_run_prints_its_prediction(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    out = tmp_path / "short.mcap"
    result = labstand("run", *SHORT, "-o", out)
    assert result.code == 0, result.err
    (line,) = [x for x in result.out.splitlines() if x.startswith("  prediction: ")]
    assert "weight travel" in line and "worst of 9 runs of the nominal model" in line
    assert "warning" not in result.err
    meta = open_recording(out).metadata
    assert OVERRIDE_TAG not in meta.tags


def test_the_override_is_stored_in_the_recording(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    # rectangular 10 mm steps at 1.5 Hz with the light weight: slack beyond the limit in
    # the worst case of the range, not at the model's own values (the run ends done)
    out = tmp_path / "override.mcap"
    motion = ["--signal", "rectangular", "--amplitude-mm", "10", "--frequency-hz", "1.5"]
    args = [*SHORT, *motion, "--mass-kg", "3.096", "--tag", "mine"]
    refused = labstand("run", *args, "-o", out)
    assert refused.code == ExitCode.REFUSED, refused.err
    assert "fibre slack" in refused.last_error_line and not out.exists()
    result = labstand("run", *args, "--override-prediction", "-o", out)
    assert result.code in (0, ExitCode.ESTOP), result.err
    assert "labstand: warning: prediction overridden: fibre slack" in result.err
    rec = open_recording(out)
    assert rec.metadata.tags == ("mine", OVERRIDE_TAG)
    notes = list(rec.events().query("kind == 'note'")["text"])
    assert any(n.startswith("prediction overridden by the operator: fibre slack") for n in notes)


def test_simulate_warns_and_says_so_in_json(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    result = labstand("simulate", *README)
    assert result.code == 0
    assert "warning: `labstand run` would refuse this motion: predicted weight travel" in (
        result.err
    )
    result = labstand("simulate", *README, "--json")
    prediction = json.loads(result.out)["prediction"]
    assert prediction["admissible"] is False
    assert prediction["nominal"]["weight_travel_mm"] == pytest.approx(373, abs=2)
    assert prediction["margins"]["weight_travel"] < 0
    quiet = labstand("simulate", "--situation", "11", "--json")
    assert quiet.err == "" and json.loads(quiet.out)["prediction"]["admissible"] is True


def _diagnosis(
    path: Path, scales: tuple[float, float, float], width: float, **extra: object
) -> Path:
    names = ("stiffness_scale", "damping_scale", "friction_scale")
    data = {
        "effect": "none",
        "effects": [],
        "ranking": [],
        "baseline_fit": dict(zip(names, scales, strict=True)),
        "baseline_intervals": {
            n: [s * (1 - width), s * (1 + width)] for n, s in zip(names, scales, strict=True)
        },
        **extra,
    }
    path.write_text(json.dumps(data))
    return path


def test_a_diagnosis_narrows_the_range_and_names_its_effects(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    # a 30 mm trapezoid at 1.5 Hz, heavy weight: beyond the slack limit only at the
    # nominal range's worst corner; a diagnosis that pins the model admits it
    motion = ["--signal", "trapezoidal", "--amplitude-mm", "30", "--frequency-hz", "1.5"]
    args = ["simulate", *motion, "--cycles", "2", "--mass-kg", "8.131", "--json"]
    nominal = json.loads(labstand(*args).out)["prediction"]
    assert nominal["admissible"] is False
    tight = _diagnosis(tmp_path / "tight.json", (1.0, 1.0, 1.0), 0.02)
    fitted = json.loads(labstand(*args, "--diagnosis", tight).out)["prediction"]
    assert fitted["admissible"] is True and "the diagnosis" in fitted["model"]
    assert fitted["nominal"] == pytest.approx(nominal["nominal"])
    effect = {"effect": "fibre_viscoelastic", "params": {"branch_stiffness_n_m": 20000.0}}
    named = _diagnosis(tmp_path / "named.json", (1.0, 1.0, 1.0), 0.02, effects=[effect])
    with_effect = json.loads(labstand(*args, "--diagnosis", named).out)["prediction"]
    assert "fibre_viscoelastic:branch_stiffness_n_m=20000" in with_effect["model"]
    # the relaxation branch takes up the snatches: the model that predicts is the fitted one
    peak = with_effect["nominal"]["peak_tension_n"]
    assert abs(peak / fitted["nominal"]["peak_tension_n"] - 1) > 0.1


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("not json", "not JSON"),
        ('{"effect": "none"}', "no baseline_fit"),
        (
            '{"baseline_fit": {"stiffness_scale": 1, "damping_scale": 1, "friction_scale": -1}}',
            "baseline_fit.friction_scale must be ≥ 0, got -1",
        ),
        (
            '{"baseline_fit": {"stiffness_scale": 1, "damping_scale": 1, "friction_scale": 1},'
            ' "effects": [{"effect": "gremlins", "params": {}}]}',
            "unknown effect 'gremlins'",
        ),
    ],
)
def test_an_unusable_diagnosis_is_one_line_and_exit_2(
    labstand: Callable[..., Outcome], tmp_path: Path, content: str, message: str
) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(content)
    result = labstand("run", *SHORT, "--diagnosis", bad, "-o", tmp_path / "x.mcap")
    assert result.code == ExitCode.USAGE
    assert message in result.last_error_line
    assert "expected the output of `labstand diagnose --json`" in result.last_error_line
    assert not (tmp_path / "x.mcap").exists()
