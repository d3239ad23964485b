"""The diagnosis as an HTML page that answers which effect, how sure, how far and where.

The first screen answers the four questions (``diagnosis_html``); the details follow
(``diagnosis_details``); the plots are ``diagnosis_plots`` and ``diagnosis_charts``.
The page loads nothing from the network: its images are files beside it.
"""

from __future__ import annotations

import html
import json
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from labstand import diagnosis_charts as charts
from labstand import diagnosis_plots as plots
from labstand.diagnosis_details import (
    provenance_section,
    ranking_section,
    recording_section,
    remainder_section,
    where_tables,
)
from labstand.diagnosis_html import first_screen, number
from sim.identify import Diagnosis, Trace

__all__ = ["report_json", "write_report"]

_STYLE = """body{font-family:sans-serif;max-width:1200px;margin:auto;padding:0 10px}
h1{font-size:1.5em;margin:8px 0 0} h2{font-size:1.15em;margin:6px 0}
header p{margin:2px 0 6px}
.grid{display:grid;grid-template-columns:minmax(0,1fr) minmax(0,1fr);gap:8px}
.grid section{border:1px solid #ccc;border-radius:4px;padding:4px 10px;overflow-x:auto}
td,th{padding:2px 8px;text-align:left;vertical-align:top}
table{border-collapse:collapse;margin:6px 0}
tr:nth-child(even){background:#f3f3f3} tr.total{border-top:1px solid #999}
img{max-width:100%} .muted{color:#666;font-size:.9em} .verdict{font-size:1.1em}
.bound{background:#fde2b8;color:#7a3e00;padding:0 4px;border-radius:3px;font-size:.85em}
.hash{font-size:.75em;word-break:break-all} td.num{text-align:right}
.grid table{font-size:.9em} .iv{white-space:nowrap}
.grid th[colspan]{background:#e8eef6}"""


def report_json(result: Diagnosis, provenance: Mapping[str, Any] | None) -> dict[str, Any]:
    """The diagnosis as JSON with its provenance: result.json and ``diagnose --json``."""
    out = result.to_dict()
    out["provenance"] = dict(provenance) if provenance is not None else None
    return out


def write_report(
    directory: Path,
    traces: Sequence[Trace],
    result: Diagnosis,
    provenance: Mapping[str, Any] | None = None,
) -> Path:
    """Write index.html, its PNGs and result.json into directory; returns index.html.

    ``provenance``: ``labstand.provenance.build_provenance``'s dict (None: not recorded).

    Written into a hidden folder beside it and renamed at the end, so an interruption
    (Ctrl-C, SIGTERM, a failed plot) leaves no partial report: a new directory appears
    whole or not at all; into an existing one the files are moved one by one, each whole.
    """
    directory.parent.mkdir(parents=True, exist_ok=True)
    work = Path(
        tempfile.mkdtemp(prefix=f".{directory.name}.", suffix=".partial", dir=directory.parent)
    )
    try:
        _write_into(work, traces, result, provenance)
        if not directory.exists():
            os.replace(work, directory)
        else:
            for item in sorted(work.iterdir()):
                os.replace(item, directory / item.name)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return directory / "index.html"


def _write_into(
    directory: Path,
    traces: Sequence[Trace],
    result: Diagnosis,
    provenance: Mapping[str, Any] | None,
) -> None:
    plots.residual_plot(directory / "residual.png", traces, result)
    charts.ranking_plot(directory / "ranking.png", result)
    charts.where_plot(directory / "where.png", result)
    plots.overlay_plot(directory / "overlay.png", traces, result)
    remainder = plots.remainder_plot(directory / "remainder.png", traces, result)
    per_recording = charts.per_recording_plot(directory / "per_recording.png", result)
    report = report_json(result, provenance)
    (directory / "result.json").write_text(json.dumps(report, indent=2))
    baseline = "".join(
        f"<tr><th>{html.escape(k)}</th><td>{number(v)}</td></tr>"
        for k, v in result.baseline.items()
    )
    title = " + ".join(e.effect for e in result.effects) or "none"
    page = f"""<!doctype html>
<html><head><meta charset="utf-8"><title>labstand diagnosis: {html.escape(title)}</title>
<style>{_STYLE}</style>
</head><body>
{first_screen(result, provenance)}
{ranking_section(result)}
{remainder_section(result, remainder)}
{recording_section(result, per_recording)}
<h2 id="where-details">Where the gap lies, over time</h2>
<p>The fitted baseline's residual over each recording, coloured by the phase of the drive
motion; held-out cycles shaded.</p>
<img src="residual.png" alt="residual over time coloured by phase">
{where_tables(result)}
<h2 id="overlay">Recorded, baseline and augmented model</h2>
<p>Left: the residuals over each recording; right: where the baseline misses most.</p>
<img src="overlay.png" alt="residuals and a zoomed overlay">
<h2 id="baseline">Fitted baseline</h2><table>{baseline}</table>
{provenance_section(provenance, result)}
</body></html>
"""
    (directory / "index.html").write_text(page, encoding="utf-8")
