"""The report's summary charts: the ranking, where the gap lies, parameters per recording."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from labstand.plots import pyplot
from sim.identify import Diagnosis

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "CLIP_CLOSURE",
    "per_recording_figure",
    "per_recording_plot",
    "ranking_figure",
    "ranking_plot",
    "where_plot",
]

#: The ranking's axis starts here: a candidate that makes the held-out error several
#: times worse would squash every other bar; its bar ends here, marked and labelled.
CLIP_CLOSURE = -1.0
#: Characters in a line of a per-recording panel's title (3.9 in wide at 8 pt).
TITLE_WIDTH = 44
#: Colours of the categories of each breakdown (phase, regime, band), in their order.
_PALETTE = ("tab:red", "tab:orange", "tab:blue", "tab:gray", "tab:green", "tab:purple")


def ranking_plot(path: Path, result: Diagnosis) -> None:
    """``ranking_figure`` into a PNG."""
    fig = ranking_figure(result)
    fig.savefig(path, dpi=90)
    pyplot().close(fig)


def ranking_figure(result: Diagnosis) -> Figure:
    """Each candidate alone on the baseline: its held-out gap closure and screening share.

    Closures below ``CLIP_CLOSURE`` are drawn to it, hatched, with the real value written
    beside; a candidate that was not refitted has no closure bar.
    """
    plt = pyplot()
    names = [r.effect for r in result.ranking]
    fig, ax = plt.subplots(figsize=(9, 0.42 * len(names) + 1.6), layout="constrained")
    y = np.arange(len(names))[::-1].astype(float)
    screening = [r.screening for r in result.ranking]
    ax.barh(y + 0.2, screening, height=0.36, color="0.7", label="screening (share of residual)")
    named = {e.effect for e in result.effects}
    for yi, line in zip(y, result.ranking, strict=True):
        if line.score is None:
            ax.text(0.01, yi - 0.2, "not refitted", va="center", fontsize=8, color="0.4")
            continue
        clipped = line.score < CLIP_CLOSURE
        shown = max(line.score, CLIP_CLOSURE)
        colour = "tab:green" if line.score >= 0 else "tab:red"
        ax.barh(yi - 0.2, shown, height=0.36, color=colour, hatch="//" if clipped else None,
                edgecolor="k" if clipped else colour, lw=0.5)  # fmt: skip
        label = f"{line.score:+.2f}" + (" (clipped)" if clipped else "")
        if line.effect in named and line.p_family is not None:
            label += f"  p = {line.p_family:.2g}"
        # Right of the bar's end, or of zero for a negative bar (never over a bar).
        ax.text(max(shown, 0.0) + 0.02, yi - 0.2, label, va="center", fontsize=8)
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_yticks(y, names)
    for tick, name in zip(ax.get_yticklabels(), names, strict=True):
        if name in named:
            tick.set_fontweight("bold")
    low = min([0.0, *(max(r.score, CLIP_CLOSURE) for r in result.ranking if r.score is not None)])
    ax.set_xlim(low - 0.08, 1.45)
    ax.set_xlabel("held-out gap closure (1 = to the noise; < 0: worse than the baseline)")
    any_clipped = any(r.score is not None and r.score < CLIP_CLOSURE for r in result.ranking)
    ax.legend(handles=_ranking_legend(any_clipped), fontsize=8, loc="lower right")
    answer = " + ".join(e.effect for e in result.effects)
    title = f"named: {answer} (bold)" if answer else "none named"
    ax.set_title(f"Each candidate alone — {title}", fontsize=10, loc="left")
    return cast("Figure", fig)


def _ranking_legend(clipped: bool) -> list[Any]:
    from matplotlib.patches import Patch

    handles = [
        Patch(color="tab:green", label="held-out closure"),
        Patch(color="tab:red", label="held-out: worse than baseline"),
        Patch(color="0.7", label="screening share"),
    ]
    if clipped:
        label = f"below {CLIP_CLOSURE:g}: clipped"
        handles.append(Patch(fc="tab:red", ec="k", hatch="//", label=label))
    return handles


def where_plot(path: Path, result: Diagnosis) -> None:
    """Where the baseline's residual lies: per breakdown, one stacked bar per channel.

    Each bar's length is the channel's share of all the residual, split by the
    breakdown's categories, so the segments of one panel add up to 1 over both channels.
    """
    plt = pyplot()
    where = result.where
    panels = (("phase of the drive", where.phase), ("regime", where.regime),
              ("frequency band", where.band))  # fmt: skip
    fig, axes = plt.subplots(len(panels), 1, figsize=(6.4, 2.9), sharex=True,
                             layout="constrained")  # fmt: skip
    channels = list(where.channel)
    for ax, (title, shares) in zip(axes, panels, strict=True):
        categories = list(next(iter(shares.values()), {}))
        for yi, channel in enumerate(channels[::-1]):
            left = 0.0
            for k, category in enumerate(categories):
                width = where.channel[channel] * shares[channel].get(category, 0.0)
                ax.barh(yi, width, left=left, color=_PALETTE[k % len(_PALETTE)], height=0.7)
                if width >= 0.07:
                    ax.text(left + width / 2, yi, f"{width:.0%}", ha="center", va="center",
                            fontsize=8, color="w")  # fmt: skip
                left += width
        ax.set_yticks(range(len(channels)), [f"{c} {where.channel[c]:.0%}" for c in channels[::-1]])
        ax.set_xlim(0.0, 1.0)
        ax.set_title(title, fontsize=9, loc="left")
        ax.legend(
            handles=[_patch(_PALETTE[k % len(_PALETTE)], c) for k, c in enumerate(categories)],
            fontsize=7, ncol=len(categories), loc="upper left", bbox_to_anchor=(1.0, 1.0),
            handlelength=1.0, frameon=False, borderaxespad=0.0,
        )  # fmt: skip
        ax.tick_params(labelsize=8)
    axes[-1].set_xlabel("share of the baseline's squared residual", fontsize=8)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _patch(colour: str, label: str) -> Any:
    from matplotlib.patches import Patch

    return Patch(color=colour, label=label)


def per_recording_plot(path: Path, result: Diagnosis) -> bool:
    """``per_recording_figure`` into a PNG; False (no file) where there is nothing to draw."""
    fig = per_recording_figure(result)
    if fig is None:
        return False
    fig.savefig(path, dpi=90)
    pyplot().close(fig)
    return True


#: The suffix of a per-recording panel that shows the baseline alone (no named effects).
ALONE = " (baseline alone)"


def _per_recording_series(result: Diagnosis) -> dict[str, tuple[str, str, dict[str, Any]]]:
    """Panel name → (its part of a recording's fit, the parameter, its consistency test).

    The final model's parameters (``params``), then the baseline alone's.
    """
    fits = result.per_recording
    series: dict[str, tuple[str, str, dict[str, Any]]] = {}
    for n in sorted({n for fit in fits.values() for n in fit.get("params", {})}):
        series[n] = ("params", n, result.consistency.get(n) or {})
    alone = sorted(
        {n for f in fits.values() for n in f.get("baseline_alone", {}).get("params", {})}
    )
    for n in alone:
        series[n + ALONE] = ("baseline_alone", n, result.baseline_consistency.get(n) or {})
    return series


def _fit_of(fit: dict[str, Any], where: str) -> dict[str, Any]:
    return fit if where == "params" else fit.get("baseline_alone", {})


def per_recording_figure(result: Diagnosis) -> Figure | None:
    """Each parameter fitted per recording against its drive rate, with its interval.

    None where the diagnosis has no per-recording fits. A parameter's panel title
    carries the consistency test's p-value and the trend it names; where effects are
    named, the baseline alone's parameters follow (what the paper tuned per situation).
    Recordings without a stored drive rate are drawn side by side, numbered.
    """
    fits = result.per_recording
    series = _per_recording_series(result)
    if not series:
        return None
    plt = pyplot()
    cols = min(3, len(series))
    rows = math.ceil(len(series) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.9 * cols, 2.9 * rows), squeeze=False,
                             layout="constrained")  # fmt: skip
    recordings = list(fits)
    rates = [_number(fits[r].get("drive_rate_hz")) for r in recordings]
    by_rate = all(math.isfinite(x) for x in rates)
    xs = rates if by_rate else list(range(len(recordings)))
    for ax, (panel, (where, name, test)) in zip(axes.flat, series.items(), strict=False):
        for k, (rec, x) in enumerate(zip(recordings, xs, strict=True)):
            fit = _fit_of(fits[rec], where)
            value = _number(fit.get("params", {}).get(name))
            if not math.isfinite(value):
                continue
            lo, hi = (_number(v) for v in fit.get("intervals", {}).get(name, (value, value)))
            # no bar where the interval is missing or not finite (a point alone)
            below, above = (value - lo, hi - value) if math.isfinite(lo + hi) else (0.0, 0.0)
            err = [[max(below, 0.0)], [max(above, 0.0)]]
            ax.errorbar([x], [value], yerr=err, fmt="o", capsize=4,
                        color=_PALETTE[k % len(_PALETTE)], label=rec)  # fmt: skip
        title = _consistency_title(panel, test)
        law = result.dynamic_stiffness.get(
            "final" if where == "params" and result.effects else "baseline_alone"
        )
        curve = name == "stiffness_scale" and by_rate and bool(law)
        if curve and law:
            _storage_curve(ax, law)
            title += "\n" + _law_words(law)
        ax.set_title(title, fontsize=8, loc="left")
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
        if by_rate:
            label = "drive rate; line: strain rate [Hz]" if curve else "drive rate [Hz]"
            ax.set_xlabel(label, fontsize=8)
        else:
            ax.set_xticks(xs, [f"#{i + 1}" for i in xs])
            ax.set_xlabel("recording (no drive rate stored)", fontsize=8)
    for ax in list(axes.flat)[len(series) :]:
        ax.set_axis_off()
    legend: dict[str, Any] = {}
    for ax in axes.flat:  # each label once: the recordings, and the law's curves
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            legend.setdefault(label, handle)
    fig.legend(list(legend.values()), list(legend), loc="outside upper center",
               ncol=min(len(legend), 4), fontsize=8)  # fmt: skip
    return cast("Figure", fig)


def _storage_curve(ax: Any, rate: dict[str, Any] | None) -> None:
    """The fibre's storage stiffness against its strain rate, with its 95 % band."""
    if not rate or not rate.get("frequencies_hz"):
        return
    f = [_number(v) for v in rate["frequencies_hz"]]
    low, high = zip(*rate["intervals"], strict=True)
    colour = "#444444" if rate.get("rises_with_rate") else "#999999"
    ax.fill_between(f, low, high, color=colour, alpha=0.15, linewidth=0)
    ax.plot(f, rate["stiffness_scale"], color=colour, linewidth=1.2,
            label="fibre's law: stiffness at each strain rate [Hz]")  # fmt: skip
    ax.plot(f, rate["model_stiffness_scale"], color=colour, linewidth=0.8, linestyle=":",
            label="the model's own, read the same way")  # fmt: skip
    ax.set_xscale("log")


def _law_words(law: dict[str, Any]) -> str:
    """One title line: what the fibre's law says of the stiffness against the strain rate."""
    share = law.get("explained_share")
    if share is not None:
        return f"law: the model has {share:.0%} of its rise"
    if law.get("rises_with_rate"):
        return f"law: rises with strain rate (p {_number(law.get('p_rise')):.2g})"
    return "law: no rise beyond the model's"


def _consistency_title(name: str, test: dict[str, Any] | None) -> str:
    """The panel's title, wrapped to stay inside the panel: name, p-value, trend."""
    effect, _, param = name.rpartition(".")
    lines = [param, f"({effect})"] if effect else [param]
    if test:
        p = _number(test.get("p_value"))
        trend = test.get("trend")
        words = [f"agree: p = {p:.2g}"] if math.isfinite(p) else []
        words += [str(trend)] if trend else []
        lines += textwrap.wrap("; ".join(words), TITLE_WIDTH)
    return "\n".join(line if len(line) <= TITLE_WIDTH else line[: TITLE_WIDTH - 1] + "…"
                     for line in lines)  # fmt: skip


def _number(value: object) -> float:
    """A JSON number as float; NaN for anything else (a missing rate, None)."""
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return math.nan
