"""End to end: ``labstand run --backend sim`` records a clean 10 s run that replays."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from recordings import open_recording
from sim.config import config_from_dict
from tests.run.conftest import SHORT, Outcome

#: 0.5 s rest, 8 trapezoidal cycles at 1 Hz (A = 30 mm), 1.5 s rest: 10 s of profile.
TEN_SECONDS = [
    "--backend", "sim", "--signal", "trapezoidal", "--amplitude-mm", "30",
    "--frequency-hz", "1", "--cycles", "8", "--dwell-start-s", "0.5", "--dwell-end-s", "1.5",
]  # fmt: skip


def test_ten_second_run_is_complete_and_replays(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    out = tmp_path / "run.mcap"
    result = labstand("run", *TEN_SECONDS, "--mass-kg", "3.096", "--note", "e2e", "-o", out)
    assert result.code == 0, result.err
    assert "Done: drive disabled" in result.out
    assert "0 lost, 0 corrupt" in result.out

    rec = open_recording(out)
    g = rec.gauges
    # 2 kHz with zero lost samples: contiguous sequence, evenly spaced device time
    assert len(g) >= 10.0 * 2000
    assert np.all(np.diff(g["seq"]) == 1)
    assert np.all(np.diff(g["t_ns"]) == 500_000)
    assert rec.lost_samples == 0
    # the command stream is the planned profile at the gauge clock, just ahead of x
    assert np.array_equal(rec.command["t_ns"], g["t_ns"])
    x, cmd = g["x_mm"], rec.command["x_cmd_mm"]
    assert abs(cmd.max() - 30.0) < 1e-9 and abs(x.max() - 30.0) < 0.1
    lag = min(range(-40, 41), key=lambda k: float(np.sum((np.roll(cmd, k) - x) ** 2)))
    # The command is the profile placed at the gauges' clock by the host's estimate of
    # when the drive started (host → device time), good to a sample: on a loaded machine
    # x has led it by one (0.5 ms), never more.
    assert -1 <= lag <= 20, f"x lags the command by {lag / 2:g} ms"
    assert np.abs(np.roll(cmd, lag) - x)[100:-100].max() < 0.5  # mm
    # drive polls at tens of Hz with position and status; enabled while running
    d = rec.drive
    assert len(d) >= 15 * 10
    assert np.all(np.diff(d["t_ns"]) >= 0)
    assert d["position_mm"].max() > 29.0 and d["enabled"].any()
    assert not d["enabled"][-1] and d["trip_code"].max() == 0
    kinds = list(rec.events()["kind"])
    assert kinds[:2] == ["note", "start"] and "stop" in kinds
    # metadata: the stand with the mass actually on it, the signal, backend, note
    meta = rec.metadata
    assert (meta.backend, meta.operator_note, meta.effects) == ("sim", "e2e", ())
    assert meta.signal is not None and meta.signal["shape"] == "trapezoidal"
    assert config_from_dict(meta.stand_config).default_mass_kg == 3.096

    replay = labstand("replay", out, "--json")
    assert replay.code == 0, replay.err
    metrics = json.loads(replay.out)["channels"]
    # measured on this run: R(u) = 1.000000, NRMSE(u) ≈ 1e-4, NRMSE(F) ≈ 1e-3
    assert metrics["u"]["R"] > 0.999
    assert metrics["u"]["nrmse"] < 0.01
    assert metrics["F"]["nrmse"] < 0.02


def test_an_effect_with_parameters_reaches_the_simulated_gauges(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    out = tmp_path / "gain.mcap"
    effect = "dial_gauge_calibration:gain_error=0.03,offset_m=0"
    result = labstand("run", *SHORT, "--effect", effect, "-o", out)
    assert result.code == 0, result.err
    (recorded,) = open_recording(out).metadata.effects
    assert recorded.name == "dial_gauge_calibration"
    assert recorded.params["gain_error"] == 0.03
    # A dial gauge reading 3 % high: u is off the model by its gain, F untouched.
    replay = labstand("replay", out, "--json")
    metrics = json.loads(replay.out)["channels"]
    assert metrics["u"]["nrmse"] > 0.005
    assert metrics["F"]["nrmse"] < 0.02
