"""The Foxglove layouts shipped in docs/foxglove/, built with the SDK's layout types.

``live_layout()`` is for ``labstand run --foxglove`` and ``labstand play``: x (measured
and planned), u and F each with the model over the measurement, the residuals, the
event log and the drive's state. ``recording_layout()`` is for an MCAP file opened in
Foxglove: every sample of the batches, plotted against their ``t_s``.

    python -m labstand.live.layouts docs/foxglove     # rewrite the shipped files
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import foxglove.layouts as fl

__all__ = ["LAYOUTS", "live_layout", "recording_layout"]

#: Seconds of the live plots' sliding window.
WINDOW_S = 10.0
_MEASURED, _MODEL, _PLAN = "#1f77b4", "#ff7f0e", "#7f7f7f"


def _plot(title: str, y_label: str, *series: fl.PlotSeries, live: bool = True) -> fl.PlotPanel:
    config = fl.PlotConfig(paths=list(series), y_axis_label=y_label, show_legend=True)
    if live:
        config.time_window_mode = "sliding"
        config.following_view_width = WINDOW_S
    return fl.PlotPanel(title=title, config=config)


def _column(*panels: fl.BasePanel, proportions: tuple[float, ...] = ()) -> fl.SplitContainer:
    sizes = proportions or (1.0,) * len(panels)
    return fl.SplitContainer(
        direction="column",
        items=[fl.SplitItem(proportion=p, content=c) for p, c in zip(sizes, panels, strict=True)],
    )


def live_layout() -> fl.Layout:
    """Plots of the live topics (``labstand.live.server``) over the last WINDOW_S."""
    s = fl.PlotSeries
    plots = _column(
        _plot(
            "drive position x",
            "mm",
            s(value="/gauges.x_mm", label="x measured", color=_MEASURED),
            s(value="/command.x_cmd_mm", label="x planned", color=_PLAN, line_style="dashed"),
        ),
        _plot(
            "weight displacement u: measured and model",
            "mm",
            s(value="/gauges.u_mm", label="u measured", color=_MEASURED),
            s(value="/model.u_mm", label="u model", color=_MODEL),
        ),
        _plot(
            "fibre force F: measured and model",
            "N",
            s(value="/gauges.force_n", label="F measured", color=_MEASURED),
            s(value="/model.force_n", label="F model", color=_MODEL),
        ),
        _plot(
            "residual u (measured − model)",
            "mm",
            s(value="/model/residual.u_mm", label="u residual"),
        ),
        _plot(
            "residual F (measured − model)",
            "N",
            s(value="/model/residual.force_n", label="F residual"),
        ),
        proportions=(1, 1.3, 1.3, 0.8, 0.8),
    )
    side = _column(
        fl.LogPanel(title="events", config=fl.LogConfig(topic_to_render="/events")),
        fl.RawMessagesPanel(title="drive", config=fl.RawMessagesConfig(topic_path="/drive")),
        proportions=(1.5, 1),
    )
    return fl.Layout(
        content=fl.SplitContainer(
            direction="row",
            items=[fl.SplitItem(proportion=3, content=plots), fl.SplitItem(content=side)],
        )
    )


def recording_layout() -> fl.Layout:
    """Every sample of a recording's batches, against their time in s (``t_s``)."""

    def full_rate(title: str, unit: str, *series: tuple[str, str, str]) -> fl.PlotPanel:
        paths = [
            fl.PlotSeries(
                value=f"{topic}.{name}[:]",
                x_value_path=f"{topic}.t_s[:]",  # paired with the values sample by sample
                label=label,
                show_line=True,
            )
            for topic, name, label in series
        ]
        panel = _plot(title, unit, *paths, live=False)
        panel.config.x_axis_val = "custom"  # x from a message path ("Message path" mode)
        panel.config.time_range = "all"
        panel.config.x_axis_label = "t (s)"
        return panel

    plots = _column(
        full_rate(
            "drive position x",
            "mm",
            ("/gauges", "x_mm", "x"),
            ("/command", "x_cmd_mm", "x planned"),
        ),
        full_rate("weight displacement u", "mm", ("/gauges", "u_mm", "u")),
        full_rate("fibre force F", "N", ("/gauges", "force_n", "F")),
    )
    side = _column(
        fl.RawMessagesPanel(title="events", config=fl.RawMessagesConfig(topic_path="/events")),
        fl.RawMessagesPanel(title="drive", config=fl.RawMessagesConfig(topic_path="/drive")),
    )
    return fl.Layout(
        content=fl.SplitContainer(
            direction="row",
            items=[fl.SplitItem(proportion=3, content=plots), fl.SplitItem(content=side)],
        )
    )


#: File name in docs/foxglove/ -> layout.
LAYOUTS = {"live-layout.json": live_layout, "recording-layout.json": recording_layout}


def render(layout: fl.Layout) -> str:
    """The layout as the JSON file Foxglove imports (indented, for review)."""
    return json.dumps(json.loads(layout.to_json()), indent=2, ensure_ascii=False) + "\n"


def main(argv: list[str]) -> int:
    """Write every layout into the folder given."""
    folder = Path(argv[0] if argv else "docs/foxglove")
    folder.mkdir(parents=True, exist_ok=True)
    for name, make in LAYOUTS.items():
        (folder / name).write_text(render(make()), encoding="utf-8")
        print(f"wrote {folder / name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
