"""An interrupted ``diagnose --report DIR`` leaves no partial DIR (written aside, renamed)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from labstand import diagnosis_charts, diagnosis_plots, diagnosis_report


def _interrupted_at_the_second_plot(monkeypatch: pytest.MonkeyPatch) -> None:
    def first(path: Path, *_: Any) -> None:
        path.write_bytes(b"png")

    def second(path: Path, *_: Any) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(diagnosis_plots, "residual_plot", first)
    monkeypatch.setattr(diagnosis_charts, "ranking_plot", second)


def test_an_interrupted_report_leaves_no_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _interrupted_at_the_second_plot(monkeypatch)
    report = tmp_path / "diagnosis"
    with pytest.raises(KeyboardInterrupt):
        diagnosis_report.write_report(report, [], None)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


def test_an_interrupted_report_leaves_an_old_one_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _interrupted_at_the_second_plot(monkeypatch)
    report = tmp_path / "diagnosis"
    report.mkdir()
    (report / "residual.png").write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt):
        diagnosis_report.write_report(report, [], None)  # type: ignore[arg-type]
    assert [p.name for p in tmp_path.iterdir()] == ["diagnosis"]
    assert (report / "residual.png").read_bytes() == b"old"
