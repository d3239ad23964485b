"""The diagnosis as an HTML page with plots a person reads at a glance."""

from __future__ import annotations

import html
import json
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from labstand.plots import pyplot, r_text
from sim.identify import Diagnosis, Trace
from sim.identify.traces import PHASES

PHASE_COLOURS = {"rise": "tab:red", "hold": "tab:orange", "fall": "tab:blue", "rest": "tab:gray"}


def _residual_plot(path: Path, traces: Sequence[Trace], result: Diagnosis) -> None:
    plt = pyplot()
    fig, axes = plt.subplots(
        2 * len(traces),
        1,
        figsize=(11, 3.2 * len(traces) + 0.4),
        squeeze=False,
        layout="constrained",
    )
    for i, (tr, out) in enumerate(zip(traces, result.outputs_before, strict=True)):
        t = np.arange(tr.samples) / tr.rate_hz
        for j, (name, rec, sim, unit) in enumerate(
            (("u", tr.u_m * 1e3, out.u_m * 1e3, "mm"), ("F", tr.force_n, out.force_n, "N"))
        ):
            ax = axes[2 * i + j, 0]
            res = np.where(tr.present, sim - rec, np.nan)
            for k, phase in enumerate(PHASES):
                sel = tr.phase == k
                ax.scatter(t[sel], res[sel], s=0.4, color=PHASE_COLOURS[phase], label=phase)
            held = ~tr.train
            ax.fill_between(
                t,
                np.nanmin(res),
                np.nanmax(res),
                where=held,
                color="k",
                alpha=0.06,
                label="held out",
            )
            ax.set_ylabel(f"{name} residual [{unit}]")
            ax.set_title(f"{tr.name}: fitted baseline − recorded", fontsize=10)
            ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncol=5, markerscale=12, fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _ranking_plot(path: Path, result: Diagnosis) -> None:
    plt = pyplot()
    names = [r.effect for r in result.ranking]
    screening = [r.screening for r in result.ranking]
    scores = [r.score if r.score is not None else 0.0 for r in result.ranking]
    fig, ax = plt.subplots(figsize=(9, 4), constrained_layout=True)
    y = np.arange(len(names))[::-1]
    ax.barh(y + 0.2, screening, height=0.4, color="tab:gray", label="screening (residual share)")
    ax.barh(y - 0.2, scores, height=0.4, color="tab:green", label="held-out gap closure (refitted)")
    ax.set_yticks(y, names)
    named = {e.effect for e in result.effects}
    for tick, name in zip(ax.get_yticklabels(), names, strict=True):
        if name in named:
            tick.set_fontweight("bold")
    ax.set_xlim(min(0.0, *scores) - 0.05, 1.05)
    ax.legend(fontsize=8, loc="lower right")
    answer = " + ".join(e.effect for e in result.effects) or "none"
    ax.set_xlabel("share (1 = all of the residual / all of the gap above the noise)")
    ax.set_title(f"Ranking (each alone) — answer: {answer} (named in bold)")
    fig.savefig(path, dpi=90)
    plt.close(fig)


#: Width of the zoomed window around the largest residual, s: narrow enough that a gap of
#: a few tenths of a millimetre on a 30 mm stroke is visible at the window's own scale.
ZOOM_S = 0.12
#: Colours shared by every panel (one legend for the figure).
RECORDED, BASELINE, AUGMENTED = "k", "tab:blue", "tab:red"


def _overlay_plot(path: Path, traces: Sequence[Trace], result: Diagnosis) -> None:
    """Per trace and channel: the residuals over the whole trace, and a zoomed overlay.

    Recorded, baseline and augmented lie within a fraction of a line width of each other
    at full scale; the residuals (model − recorded) and a window around the baseline's
    largest residual (shaded in the residual panel) show the difference a person is
    looking for.
    """
    plt = pyplot()
    from matplotlib.lines import Line2D

    fig, axes = plt.subplots(
        2 * len(traces),
        2,
        figsize=(12, 3.2 * len(traces) + 0.5),
        squeeze=False,
        layout="constrained",
        gridspec_kw={"width_ratios": [2.2, 1]},
    )
    named = " + ".join(e.effect for e in result.effects)
    for i, tr in enumerate(traces):
        t = np.arange(tr.samples) / tr.rate_hz
        before, after = result.outputs_before[i], result.outputs_after[i]
        for j, (name, unit, scale, rec, b, a) in enumerate(
            (
                ("u", "mm", 1e3, tr.u_m, before.u_m, after.u_m),
                ("F", "N", 1.0, tr.force_n, before.force_n, after.force_n),
            )
        ):
            res_b = np.where(tr.present, b - rec, np.nan) * scale
            res_a = np.where(tr.present, a - rec, np.nan) * scale
            ax = axes[2 * i + j, 0]
            ax.plot(t, res_b, color=BASELINE, lw=0.6)
            if named:
                ax.plot(t, res_a, color=AUGMENTED, lw=0.6)
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_ylabel(f"Δ{name} [{unit}]")
            ax.set_title(
                f"{tr.name}: {name}, model − recorded (shaded: the window on the right)",
                fontsize=10,
            )
            ax.grid(alpha=0.3)
            # The window around the baseline's largest residual, at its own scale.
            k = int(np.nanargmax(np.abs(res_b))) if np.isfinite(res_b).any() else 0
            half = int(ZOOM_S / 2 * tr.rate_hz)
            win = slice(max(0, k - half), min(tr.samples, k + half))
            ax.axvspan(t[win][0], t[win][-1], color="gold", alpha=0.35, lw=0)
            zoom = axes[2 * i + j, 1]
            zoom.plot(t[win], rec[win] * scale, color=RECORDED, lw=1.2)
            zoom.plot(t[win], b[win] * scale, color=BASELINE, lw=1.1, ls="--")
            if named:
                zoom.plot(t[win], a[win] * scale, color=AUGMENTED, lw=1.1, ls=":")
            zoom.set_ylabel(f"{name} [{unit}]")
            zoom.set_title(
                f"largest baseline miss: {res_b[k]:+.3g} {unit} at t = {t[k]:.3f} s", fontsize=10
            )
            zoom.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    handles = [
        Line2D([], [], color=RECORDED, lw=1.2, label="recorded"),
        Line2D([], [], color=BASELINE, lw=1.1, ls="--", label="fitted baseline"),
    ]
    if named:
        handles.append(Line2D([], [], color=AUGMENTED, lw=1.1, ls=":", label=f"+ {named}"))
    fig.legend(handles=handles, loc="outside upper center", ncol=len(handles), fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _remainder_plot(path: Path, traces: Sequence[Trace], result: Diagnosis) -> bool:
    """The final model's remainder against what its best signature predicts (False: none).

    Per recording, each channel the signature acts in: the remainder (recorded − model)
    in grey, the signature's fit in colour, held-out cycles shaded.
    """
    rem = result.remainder
    # The model's outputs' signatures: the balances' describe forces, not these channels.
    passing = (
        [s for s in rem.signature if s.passes and s.source == "outputs"] if rem is not None else []
    )
    if rem is None or not passing:
        return False
    best = passing[0]
    fit = rem.fits[f"{best.kind} in {best.channel}"]
    channels = [c for c in ("u", "F") if c in best.channel]
    plt = pyplot()
    fig, axes = plt.subplots(
        len(traces) * len(channels), 1, figsize=(11, 2.4 * len(traces) * len(channels) + 0.6),
        squeeze=False, layout="constrained",
    )  # fmt: skip
    row = 0
    for tr, out, pred in zip(traces, result.outputs_after, fit.predicted, strict=True):
        t = np.arange(tr.samples) / tr.rate_hz
        for ch in channels:
            scale, unit = (1e3, "mm") if ch == "u" else (1.0, "N")
            rec, sim, p = (
                (tr.u_m, out.u_m, pred.u_m)
                if ch == "u"
                else (tr.force_n, out.force_n, pred.force_n)
            )
            ax = axes[row, 0]
            ax.plot(t, np.where(tr.present, rec - sim, np.nan) * scale, color="0.6", lw=0.5,
                    label="remainder (recorded − model)")  # fmt: skip
            ax.plot(t, p * scale, color="tab:red", lw=1.0, label=f"{best.kind} term")
            low, high = ax.get_ylim()
            ax.fill_between(t, low, high, where=~tr.train, color="k", alpha=0.06,
                            label="held out")  # fmt: skip
            ax.set_ylim(low, high)
            ax.set_ylabel(f"{ch} [{unit}]")
            ax.set_title(f"{tr.name}", fontsize=10, loc="left")
            ax.grid(alpha=0.3)
            row += 1
    axes[-1, 0].set_xlabel("time [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncol=3, fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def _remainder_section(result: Diagnosis, plotted: bool) -> str:
    """What remains after the named effects: the test, and the signatures that pass."""
    from sim.identify.remainder import VERDICT_WORDS

    rem = result.remainder
    if rem is None:
        return ""
    state = "beyond the noise" if rem.beyond_noise else "within what the noise allows"
    rows = "".join(
        f"<tr><td>{html.escape(s.kind)}</td><td>{html.escape(s.channel)}</td>"
        f"<td>{s.closes:.0%}</td><td>{s.p_family:.2g}</td><td>{'yes' if s.passes else 'no'}</td>"
        f"<td><code>{html.escape(s.formula)}</code></td></tr>"
        for s in rem.signature
    )
    plot = (
        '<img src="remainder.png" alt="the remainder against its best signature">'
        if plotted
        else ""
    )
    return f"""<h2>What remains</h2>
<p><b>{html.escape(VERDICT_WORDS.get(result.verdict, result.verdict))}</b>.
The remainder is {state} (family p = {rem.p_value:.2g} over the signature kinds); its
held-out error is {rem.excess:.2f} × the noise, {rem.share_of_gap:.0%} of the baseline's gap.</p>
<table><tr><th>kind</th><th>acts in</th><th>closes of the remainder</th><th>p (family)</th>
<th>evidence</th><th>fitted terms</th></tr>{rows}</table>
{plot}
"""


def _table(rows: Mapping[str, object]) -> str:
    cells = "".join(
        f"<tr><th>{html.escape(str(k))}</th><td>{_fmt(v)}</td></tr>" for k, v in rows.items()
    )
    return f"<table>{cells}</table>"


def _fmt(value: object, key: object = None) -> str:
    if isinstance(value, float):
        return r_text(value) if key == "R" else f"{value:.4g}"
    if isinstance(value, dict):
        return ", ".join(f"{html.escape(str(k))} {_fmt(v, k)}" for k, v in value.items())
    return html.escape(str(value))


def write_report(directory: Path, traces: Sequence[Trace], result: Diagnosis) -> Path:
    """Write index.html, its PNGs and result.json into directory; returns index.html.

    Written into a hidden folder beside it and renamed at the end, so an interruption
    (Ctrl-C, SIGTERM, a failed plot) leaves no partial report: a new directory appears
    whole or not at all; into an existing one the files are moved one by one, each whole.
    """
    directory.parent.mkdir(parents=True, exist_ok=True)
    work = Path(
        tempfile.mkdtemp(prefix=f".{directory.name}.", suffix=".partial", dir=directory.parent)
    )
    try:
        _write_into(work, traces, result)
        if not directory.exists():
            os.replace(work, directory)
        else:
            for item in sorted(work.iterdir()):
                os.replace(item, directory / item.name)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return directory / "index.html"


def _write_into(directory: Path, traces: Sequence[Trace], result: Diagnosis) -> None:
    _residual_plot(directory / "residual.png", traces, result)
    _ranking_plot(directory / "ranking.png", result)
    _overlay_plot(directory / "overlay.png", traces, result)
    plotted = _remainder_plot(directory / "remainder.png", traces, result)
    (directory / "result.json").write_text(json.dumps(result.to_dict(), indent=2))
    where = result.where
    ranking_rows = "".join(
        f"<tr><td>{html.escape(r.effect)}</td><td>{_fmt(r.score)}</td>"
        f"<td>{_fmt(r.screening)}</td><td>{_fmt(r.params)}"
        f"{' — at its bound: ' + html.escape(', '.join(r.at_bound)) if r.at_bound else ''}"
        "</td></tr>"
        for r in result.ranking
    )
    page = f"""<!doctype html>
<html><head><meta charset="utf-8"><title>labstand diagnosis: {html.escape(result.effect)}</title>
<style>body{{font-family:sans-serif;max-width:1150px;margin:auto}}
td,th{{padding:2px 8px;text-align:left}} table{{border-collapse:collapse;margin:6px 0}}
tr:nth-child(even){{background:#f3f3f3}}</style>
</head><body>
<h1>Diagnosis: <code>{html.escape(result.effect)}</code> ({html.escape(result.verdict)})</h1>
<p>Recordings: {", ".join(html.escape(t.name) for t in traces)}.
Held-out NRMSE {result.heldout_error_before:.4g} → {result.heldout_error_after:.4g}
(noise alone {result.noise_floor:.4g}; gap closure in noise units {result.gap_closure:.2f};
bootstrap confidence {result.confidence:.2f}).</p>
<h2>How far the gap shrinks (held-out cycles)</h2>
<h3>before</h3>{_table(result.gap_before)}<h3>after</h3>{_table(result.gap_after)}
<h2>Which effect</h2><img src="ranking.png" alt="ranking">
<table><tr><th>effect</th><th>held-out gap closure</th><th>screening</th>
<th>fitted parameters</th></tr>
{ranking_rows}</table>
{_remainder_section(result, plotted)}
<h2>Where the gap lies</h2>
<p>Shares of the fitted baseline's squared residual.</p>
<h3>by channel</h3>{_table(where.channel)}
<h3>by phase of the drive motion</h3>{_table(where.phase)}
<h3>by regime</h3>{_table(where.regime)}
<h3>by frequency band</h3>{_table(where.band)}
<img src="residual.png" alt="residual over time coloured by phase">
<h2>Recorded, baseline and augmented model</h2>
<p>Left: the residuals over each recording; right: where the baseline misses most.</p>
<img src="overlay.png" alt="residuals and a zoomed overlay">
<h2>Fitted baseline</h2>{_table(result.baseline)}
</body></html>
"""
    (directory / "index.html").write_text(page, encoding="utf-8")
