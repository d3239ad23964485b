"""Replay, compare and Table 1 on recordings the model made (truth known)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labstand.cli import main
from recordings.replay import ReplayError, align, compare_runs, replay
from sim.config import StandConfig
from sim.metrics import channel_metrics, correlation, nrmse


def test_metrics_follow_the_papers_definitions() -> None:
    rng = np.random.default_rng(0)
    rec = rng.normal(size=1000)
    # R is blind to gain and offset; NRMSE is not.
    assert correlation(rec, 3 * rec + 7) == pytest.approx(1.0)
    m = channel_metrics(rec, 1.1 * rec)
    assert pytest.approx(1.0) == m.R and m.psi == pytest.approx(0.0, abs=1e-20)
    assert m.nrmse == pytest.approx(0.1 * np.linalg.norm(rec) / np.linalg.norm(rec - rec.mean()))
    assert channel_metrics(rec, -rec).psi == pytest.approx(4.0)
    assert nrmse(rec, rec) == 0.0


def _frame(stand: StandConfig, params: str = "final", situation: str = "11") -> pd.DataFrame:
    from drivers.signals import plan_motion
    from sim.model import Model
    from sim.situations import SITUATIONS

    s = SITUATIONS[situation]
    t, x = plan_motion(s.signal, stand.drive).sample(2000.0)
    run = Model(stand.stand_params(params, s.mass_kg)).run(x, 2000.0)
    return pd.DataFrame(
        {"x_mm": x * 1e3, "u_mm": run.u_m * 1e3, "F_N": run.force_n},
        index=pd.Index(t, name="t_s"),
    )


def test_replay_with_the_generating_parameters_matches(stand: StandConfig) -> None:
    frame = _frame(stand)
    result = replay(frame, stand.stand_params("final", 8.131))
    for name in ("u", "F", "F_dyn"):
        assert result.metrics[name].R > 0.999999
        assert result.metrics[name].nrmse < 1e-3
    other = replay(frame, stand.stand_params("starting", 8.131))
    assert other.metrics["F_dyn"].R < 0.9 and other.metrics["u"].nrmse > 0.05


def test_lost_samples_are_bridged_and_left_out(stand: StandConfig) -> None:
    frame = _frame(stand)
    holed = frame.drop(frame.index[3000:3010])
    result = replay(holed, stand.stand_params("final", 8.131))
    assert result.to_dict()["lost_samples"] == 10
    assert result.metrics["u"].samples == len(frame) - 10
    assert result.metrics["u"].nrmse < 5e-3  # x interpolated over 5 ms: still close
    assert any("10 lost sample" in n for n in result.notes)


def test_compare_aligns_on_the_start_of_motion(stand: StandConfig) -> None:
    frame = _frame(stand)
    later = frame.copy()
    later.index = later.index + 0.25  # the same run, started a quarter second later
    padded = pd.concat([frame.iloc[:500].set_axis(frame.index[:500]), later])
    result = compare_runs(frame, padded)
    assert result.metrics["u"].nrmse < 1e-9


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (lambda f: f.drop(columns="u_mm"), "no u_mm channel"),
        (lambda f: f.assign(x_mm=0.0), "the drive never moves"),
        (lambda f: f.iloc[:1], "has 1 sample"),
        (lambda f: f.iloc[::-1], "not strictly increasing"),
    ],
)
def test_unreplayable_recordings_are_refused(stand: StandConfig, mutate, message: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ReplayError, match=message):
        align(mutate(_frame(stand)))


def test_replay_compare_table1_commands(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    a, b = tmp_path / "s11.csv", tmp_path / "s10.csv"
    assert main(["simulate", "--situation", "11", "-o", str(a)]) == 0
    assert main(["simulate", "--situation", "10", "-o", str(b)]) == 0
    capsys.readouterr()
    png = tmp_path / "replay.png"
    assert main(["replay", str(a), "--params", "final", "--json", "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["channels"]["u"]["R"] > 0.99999 and out["channels"]["F"]["nrmse"] < 1e-3
    assert set(out["channels"]["u"]) >= {"R", "psi", "nrmse"}
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert main(["replay", str(a), "--params", "starting", "--json"]) == 0
    worse = json.loads(capsys.readouterr().out)
    assert worse["channels"]["F"]["psi"] > out["channels"]["F"]["psi"]
    assert main(["compare", str(a), str(a), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["channels"]["F"]["nrmse"] == 0.0
    assert main(["table1", str(a), str(b), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [Path(r["recording"]).name for r in rows] == ["s11.csv", "s10.csv"]
    assert all(r["second"]["R_u"] > r["first"]["R_u"] for r in rows)  # 'final' generated them
    assert main(["table1", str(a)]) == 0
    assert "| s11.csv |" in capsys.readouterr().out
