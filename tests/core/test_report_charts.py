"""The report's summary charts draw what the diagnosis says, clipped values marked."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from labstand.diagnosis_charts import (
    CLIP_CLOSURE,
    per_recording_figure,
    per_recording_plot,
    ranking_figure,
)
from labstand.plots import pyplot
from sim.identify import Diagnosis
from sim.identify.report import AcceptedEffect, RankedEffect
from sim.identify.where import Where


def _diagnosis(ranking: list[RankedEffect]) -> Diagnosis:
    where = Where({"u": 0.5, "F": 0.5}, {}, {}, {}, {})
    gap = {"u": {"R": 0.99, "psi": 0.0, "nrmse": 0.1}, "F": {"R": 0.99, "psi": 0.0, "nrmse": 0.1}}
    return Diagnosis(
        effects=[AcceptedEffect("a", 0.9, 0.001, {})], ranking=ranking, where=where,
        gap_before=gap, gap_after=gap, baseline={}, heldout_error_before=0.1,
        heldout_error_after=0.05, noise_floor=0.01, gap_closure=0.9, confidence=1.0,
    )  # fmt: skip


def test_the_ranking_draws_each_real_closure_and_marks_those_clipped() -> None:
    result = _diagnosis(
        [
            RankedEffect("a", 0.3, 0.9, p_family=0.001),
            RankedEffect("b", 0.2, -0.4),
            RankedEffect("c", 0.1, -6.25),
            RankedEffect("d", 0.0),  # not refitted: no closure bar
        ]
    )
    fig = ranking_figure(result)
    try:
        ax = fig.axes[0]
        texts = [t.get_text() for t in ax.texts]
        widths = {round(p.get_width(), 6) for p in ax.patches}  # closure and screening bars
        assert {0.9, -0.4, CLIP_CLOSURE} <= widths  # the real values, -6.25 drawn to the clip
        assert min(widths) == CLIP_CLOSURE
        assert "-6.25 (clipped)" in texts and "-0.40" in texts
        assert any(t.startswith("+0.90") and "p = 0.001" in t for t in texts)
        assert "not refitted" in texts
        assert ax.get_xlim()[0] < CLIP_CLOSURE
    finally:
        pyplot().close(fig)


def test_parameters_per_recording_are_drawn_by_rate_or_side_by_side(tmp_path: Path) -> None:
    result = _diagnosis([])
    assert per_recording_figure(result) is None
    assert not per_recording_plot(tmp_path / "none.png", result)
    assert not (tmp_path / "none.png").exists()

    result.per_recording = {
        "quick": {"params": {"k": 1.2}, "intervals": {"k": (1.1, 1.4)}, "drive_rate_hz": 2.0},
        "slow": {"params": {"k": 1.0}, "intervals": {"k": (0.9, 1.05)}, "drive_rate_hz": 0.5},
    }
    result.consistency = {"k": {"p_value": 0.004, "trend": "grows with the drive rate"}}
    fig = per_recording_figure(result)
    assert fig is not None
    try:
        ax = fig.axes[0]
        assert ax.get_xlabel() == "drive rate [Hz]"
        assert "p = 0.004" in ax.get_title(loc="left") and "grows" in ax.get_title(loc="left")
        # each point at its rate, its error bar spanning the interval
        points = {tuple(line.get_xydata()[0]) for line in ax.lines if len(line.get_xdata()) == 1}
        assert {(2.0, 1.2), (0.5, 1.0)} <= points
        spans = [c.get_segments()[0] for c in ax.collections]
        lows_highs = {(round(s[0][1], 6), round(s[1][1], 6)) for s in spans}
        assert {(1.1, 1.4), (0.9, 1.05)} <= lows_highs
    finally:
        pyplot().close(fig)

    # No drive rate stored and an interval that is not finite: drawn side by side, no bar.
    result.per_recording["slow"].pop("drive_rate_hz")
    result.per_recording["slow"]["intervals"] = {"k": (math.nan, 1.05)}
    fig = per_recording_figure(result)
    assert fig is not None
    try:
        assert fig.axes[0].get_xlabel() == "recording (no drive rate stored)"
    finally:
        pyplot().close(fig)
    assert per_recording_plot(tmp_path / "pr.png", result)
    assert (tmp_path / "pr.png").read_bytes()[:4] == b"\x89PNG"


def test_the_baseline_alone_per_recording_follows_the_final_model() -> None:
    # The paper's question: the stiffness a baseline alone needs per test, and whether it
    # moves with the rate, drawn after the final model's parameters with its own test.
    result = _diagnosis([])
    result.per_recording = {
        name: {"params": {"k": 1.0}, "intervals": {"k": (0.9, 1.1)}, "drive_rate_hz": rate,
               "baseline_alone": {"params": {"stiffness_scale": alone},
                                  "intervals": {"stiffness_scale": (alone - 0.01, alone + 0.01)}}}
        for name, rate, alone in (("quick", 2.0, 1.3), ("slow", 0.5, 1.1))
    }  # fmt: skip
    result.baseline_consistency = {"stiffness_scale": {"p_value": 1e-5, "trend": "rises"}}
    fig = per_recording_figure(result)
    assert fig is not None
    try:
        titles = [ax.get_title(loc="left") for ax in fig.axes if ax.lines]
        assert titles[0].startswith("k") and "(baseline alone)" in titles[1]
        assert "p = 1e-05" in titles[1] and "rises" in titles[1]
        alone = fig.axes[1]
        points = {tuple(line.get_xydata()[0]) for line in alone.lines if len(line.get_xdata()) == 1}
        assert {(2.0, 1.3), (0.5, 1.1)} <= points
    finally:
        pyplot().close(fig)


def test_the_fibres_stiffness_per_strain_rate_is_drawn_in_the_stiffness_panel() -> None:
    result = _diagnosis([])
    result.per_recording = {
        name: {"params": {"stiffness_scale": k}, "drive_rate_hz": rate,
               "intervals": {"stiffness_scale": (k - 0.01, k + 0.01)}}
        for name, rate, k in (("quick", 2.0, 1.3), ("slow", 0.5, 1.1))
    }  # fmt: skip
    result.effects = []
    curve = [1.0, 1.1, 1.4]
    result.dynamic_stiffness = {"baseline_alone": {
        "frequencies_hz": [0.4, 2.0, 10.0], "stiffness_scale": curve,
        "intervals": [[0.95, 1.05], [1.05, 1.15], [1.3, 1.5]],
        "model_stiffness_scale": [1.2, 1.2, 1.2], "rises_with_rate": True,
    }}  # fmt: skip
    fig = per_recording_figure(result)
    assert fig is not None
    try:
        ax = fig.axes[0]
        drawn = [list(line.get_ydata()) for line in ax.lines if len(line.get_xdata()) == 3]
        assert curve in drawn and [1.2, 1.2, 1.2] in drawn
        assert ax.get_xscale() == "log"
        labels = [t.get_text() for t in fig.legends[0].get_texts()]
        assert "quick" in labels and any("strain rate" in t for t in labels)
    finally:
        pyplot().close(fig)


@pytest.mark.parametrize("name", ["x" * 80, "short"])
def test_a_long_recording_name_is_shortened_in_titles(name: str) -> None:
    from labstand.diagnosis_plots import TITLE_NAME, short_name

    shown = short_name(name)
    assert len(shown) <= TITLE_NAME
    if len(name) <= TITLE_NAME:
        assert shown == name
    else:
        assert shown.startswith("xxx") and shown.endswith("xxx") and "…" in shown
