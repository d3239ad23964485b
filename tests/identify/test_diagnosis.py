"""The diagnosis: input checks, segmentation, and blind answers on generated campaigns."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labstand.campaigns import trace_of
from labstand.cli import main
from sim.checks.check import SMALL_CAMPAIGN, Case, CheckResult, make_campaign, run_check
from sim.config import StandConfig
from sim.identify import DiagnosisInputError, diagnose
from sim.identify.traces import PHASE_FALL, PHASE_HOLD, PHASE_REST, PHASE_RISE


def _frame(t: np.ndarray, x: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame(
        {"x_mm": x * 1e3, "u_mm": x * 1e3, "F_N": 40 + 0 * x}, index=pd.Index(t, name="t_s")
    )


def test_phases_and_cycles_follow_the_drive(stand: StandConfig) -> None:
    traces, _, _ = make_campaign(stand, "none", 8.131, np.random.default_rng(0), SMALL_CAMPAIGN)
    quick = traces[0]
    assert int(quick.cycle.max()) + 1 == 4  # four cycles
    assert {PHASE_RISE, PHASE_HOLD, PHASE_FALL, PHASE_REST} <= set(np.unique(quick.phase))
    assert quick.phase[0] == PHASE_REST
    # Interleaved hold-out: odd cycles are held out, even cycles train.
    for k in range(4):
        in_cycle = quick.cycle == k
        assert np.all(quick.train[in_cycle] == (k % 2 == 0))
    assert quick.noise_force_n > 0.01  # the drawn gauge noise is seen during the rest


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda t: _frame(t[:1000], np.linspace(0, 0.02, 1000)), "too short to fit"),
        (lambda t: _frame(t, np.zeros_like(t)), "the drive never moves"),
        (lambda t: _frame(t, 1e-4 * np.sin(t)), "a flat drive signal excites nothing"),
        (lambda t: _frame(t, 0.02 * np.sin(t)).drop(columns="F_N"), "no F_N channel"),
    ],
)
def test_undiagnosable_input_says_what_is_missing(make, message: str) -> None:  # type: ignore[no-untyped-def]
    t = np.arange(8000) / 2000.0
    with pytest.raises(DiagnosisInputError, match=message):
        trace_of("rec.csv", make(t), 8.131)


def test_a_dial_gauge_gain_error_is_found_and_the_gap_shrinks(stand: StandConfig) -> None:
    rng = np.random.default_rng(3)
    traces, _, params = make_campaign(stand, "dial_gauge_calibration", 8.131, rng, SMALL_CAMPAIGN)
    result = diagnose(traces, stand.stand_params("final", 8.131))
    assert result.effect == "dial_gauge_calibration"
    assert result.ranking[0].effect == "dial_gauge_calibration"
    fitted = result.ranking[0].params["gain_error"]
    assert fitted == pytest.approx(params["gain_error"], abs=0.1 * abs(params["gain_error"]) + 1e-3)
    assert result.gap_after["u"]["nrmse"] < 0.8 * result.gap_before["u"]["nrmse"]
    # Segments start from the measured u, so a gain error also shows in F (the start
    # elongation is off); explaining it must not make F worse.
    assert result.gap_after["F"]["nrmse"] <= result.gap_before["F"]["nrmse"] * 1.05
    assert sum(result.where.channel.values()) == pytest.approx(1.0)


def test_where_attributes_a_residual_to_its_channel_phase_regime_and_band(
    stand: StandConfig,
) -> None:
    from sim.identify.where import SimStates, where_the_gap_lies

    traces, _, _ = make_campaign(stand, "none", 8.131, np.random.default_rng(1), SMALL_CAMPAIGN)
    tr = traces[0]
    t = np.arange(tr.samples) / tr.rate_hz
    u = np.where(tr.present, tr.u_m, 0.0)
    f = np.where(tr.present, tr.force_n, 0.0)
    # A model that is exact but for a 50 Hz force error while the drive falls.
    error = np.where(tr.phase == PHASE_FALL, 0.5 * np.sin(2 * np.pi * 50 * t), 0.0)
    states = SimStates(u, f + error, np.zeros_like(u) + 0.1)
    where = where_the_gap_lies([tr], [states])
    assert where.channel["F"] == pytest.approx(1.0)
    assert where.phase["F"]["fall"] == pytest.approx(1.0)
    assert where.band["F"]["20-100 Hz"] > 0.7
    assert where.regime["F"]["taut"] + where.regime["F"]["snatch"] > 0.99


def test_stand_mismatch_alone_is_fitted_away_and_answered_none(stand: StandConfig) -> None:
    traces, _, _ = make_campaign(stand, "none", 8.131, np.random.default_rng(5), SMALL_CAMPAIGN)
    result = diagnose(traces, stand.stand_params("final", 8.131))
    assert result.effect == "none"
    # The fitted baseline leaves little beyond the noise floor.
    assert result.heldout_error_before < 3 * result.noise_floor


def test_diagnose_command_on_csv_recordings_with_report(
    tmp_path: Path, stand: StandConfig, capsys: pytest.CaptureFixture[str]
) -> None:
    traces, _, _ = make_campaign(
        stand, "dial_gauge_calibration", 8.131, np.random.default_rng(3), SMALL_CAMPAIGN
    )
    paths = []
    for tr in traces:
        t = np.arange(tr.samples) / tr.rate_hz
        path = tmp_path / f"{tr.name}.csv"
        np.savetxt(
            path,
            np.column_stack([t, tr.x_m * 1e3, tr.u_m * 1e3, tr.force_n]),
            delimiter=",",
            header="t_s,x_mm,u_mm,F_N",
            comments="",
        )
        paths.append(str(path))
    report = tmp_path / "report"
    assert main(["diagnose", *paths, "--mass-kg", "8.131", "--json", "--report", str(report)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["effect"] == "dial_gauge_calibration"
    assert out["mass_kg"][paths[0]] == {"kg": 8.131, "source": "--mass-kg"}
    assert {"effect", "ranking", "where", "gap_before", "gap_after"} <= set(out)
    assert set(out["gap_before"]["u"]) == {"R", "psi", "nrmse"}
    keys = {"effect", "score", "params", "p_value", "p_family"}
    assert all(keys <= set(r) for r in out["ranking"])
    # The named effect's evidence is its family p-value, what ALPHA judged.
    named = next(r for r in out["ranking"] if r["effect"] == out["effect"])
    assert out["effects"][0]["p_value"] == named["p_family"] <= 0.05
    # How sure: the contract's intervals beside the numbers they bound.
    assert set(out["baseline_intervals"]) == set(out["baseline_fit"])
    low, high = out["effects"][0]["intervals"]["gain_error"]
    assert low <= out["effects"][0]["params"]["gain_error"] <= high
    low, high = out["gap_closure_interval"]
    assert low <= out["gap_closure"] <= high
    assert set(out["per_recording"]) == {Path(p).name for p in paths}
    page = (report / "index.html").read_text()
    assert "dial_gauge_calibration" in page and 'src="ranking.png"' in page
    # Provenance: the files by their hashes, the mass and where it came from, the stand;
    # one record that --json, result.json and the page all show.
    prov = out["provenance"]
    for path, rec in zip(paths, prov["recordings"], strict=True):
        digest = hashlib.sha256(Path(path).read_bytes()).hexdigest()
        assert rec["path"] == path and rec["sha256"] == digest and digest in page
        assert (rec["mass_kg"], rec["mass_source"]) == (8.131, "--mass-kg")
        assert rec["signal"] is None  # a CSV import does not say how it was driven
    assert prov["stand"]["file"] is None and prov["stand"]["parameter_set"] == "final"
    assert prov["labstand_version"] and prov["created_utc"].startswith("20")
    assert json.loads((report / "result.json").read_text())["provenance"] == prov
    for png in ("ranking.png", "residual.png", "overlay.png"):
        assert (report / png).read_bytes()[:4] == b"\x89PNG"


def test_diagnose_command_refuses_a_flat_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "flat.csv"
    t = np.arange(6000) / 2000.0
    np.savetxt(
        path,
        np.column_stack([t, 0 * t, 0 * t, 40 + 0 * t]),
        delimiter=",",
        header="t_s,x_mm,u_mm,F_N",
        comments="",
    )
    assert main(["diagnose", str(path)]) == 2
    err = capsys.readouterr().err
    assert "flat.csv: the drive never moves" in err and err.count("\n") == 1


def test_small_blind_check_scores_its_answers(stand: StandConfig) -> None:
    result = run_check(
        stand,
        seed=11,
        classes=["none", "dial_gauge_calibration"],
        masses=[8.131],
        campaign=SMALL_CAMPAIGN,
    ).to_dict()
    assert result["cases"] == 2
    assert (
        result["confusion"]["none"]["none"] + result["confusion"]["none"]["dial_gauge_calibration"]
        == 1
    )
    assert result["accuracy"] == 1.0
    assert result["false_alarm_rate"] == 0.0
    # The diagnosis shrinks the gap about as far as the true model does.
    assert result["median_shrink"] >= 0.8 * result["oracle_median_shrink"] > 0
    # The true gauge error is itself evidence against the fitted baseline; none has none.
    identifiable = {c["truth"]: c["identifiable"] for c in result["details"]}
    assert identifiable == {"none": None, "dial_gauge_calibration": True}


def test_none_is_right_where_the_truth_itself_is_no_evidence() -> None:
    def case(truth: str, answer: str, identifiable: bool | None) -> Case:
        return Case(truth, 3.096, answer, {}, 0.0, 0.0, 1.0, identifiable)

    result = CheckResult(
        [
            case("fibre_transverse_vibration", "none", False),  # drawn too small to show
            case("fibre_pulley_jump", "none", True),  # shown, missed
            case("channel_time_skew", "force_gauge_dynamics", False),  # a wrong name stays wrong
            case("none", "none", None),
        ]
    ).to_dict()
    assert result["accuracy"] == 0.25
    assert result["accuracy_identifiable"] == 0.5
    assert result["unidentifiable"] == 2
