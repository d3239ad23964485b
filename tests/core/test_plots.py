"""Plots a scientist reads: a unit on every axis, R with the paper's six decimals."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from labstand.cli import main
from labstand.diagnosis_html import _r
from labstand.plots import pyplot, r_text, replay_figure, run_figure
from recordings import open_recording
from recordings.replay import replay
from sim.config import StandConfig
from sim.model import Model

UNIT = re.compile(r"\[[^\]]+\]$")  # "weight u [mm]", "Δ(F − T₀) [N]"


def test_r_has_six_decimals_where_four_would_read_as_one() -> None:
    assert r_text(0.9999614) == "0.999961"
    assert _r({"R": 0.9999614, "nrmse": 0.0099}) == "0.999961"  # the report's how-far table


def test_replay_figure_has_units_on_every_axis_and_six_digit_r(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], stand: StandConfig
) -> None:
    rec = tmp_path / "s11.csv"
    assert main(["simulate", "--situation", "11", "--params", "starting", "-o", str(rec)]) == 0
    capsys.readouterr()
    result = replay(open_recording(rec).frame(), stand.stand_params("final", 8.131))
    fig = replay_figure(result, "s11")
    try:
        axes = fig.get_axes()
        assert len(axes) == 4
        assert all(UNIT.search(ax.get_ylabel()) for ax in axes), [a.get_ylabel() for a in axes]
        assert axes[-1].get_xlabel() == "time [s]"
        for ax, name in ((axes[0], "u"), (axes[2], "F_dyn")):
            assert f"R = {result.metrics[name].R:.6f}," in ax.get_title()
        # the residual panels say what was subtracted from what
        residual_legends = [ax.get_legend().get_texts()[0].get_text() for ax in axes[1::2]]
        assert residual_legends == ["simulated − recorded"] * 2
    finally:
        pyplot().close(fig)


def test_run_figure_has_units_on_every_axis(stand: StandConfig) -> None:
    import numpy as np

    rate = stand.sample_rate_hz
    x_m = np.concatenate([np.zeros(200), np.linspace(0, 0.02, 400), np.full(400, 0.02)])
    fig = run_figure(Model(stand.stand_params("final")).run(x_m, rate), "ramp")
    try:
        assert all(UNIT.search(ax.get_ylabel()) for ax in fig.get_axes())
        assert fig.get_axes()[-1].get_xlabel() == "time [s]"
    finally:
        pyplot().close(fig)
