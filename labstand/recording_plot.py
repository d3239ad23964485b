"""A quick look at a recording: drive, weight and force over time, with its events."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from labstand.plots import pyplot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from recordings.recording import Recording

#: Event kinds drawn as lines (colour); others are drawn grey.
EVENT_COLOURS = {"start": "tab:green", "stop": "tab:blue", "estop": "tab:red", "fault": "tab:red"}


def plot_recording(path: Path, rec: Recording, title: str) -> None:
    """Write ``recording_figure`` as a PNG."""
    fig = recording_figure(rec, title)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)


def recording_figure(rec: Recording, title: str) -> Figure:
    """Drive x (and its command), weight u and force F, one panel each; events as lines."""
    plt = pyplot()
    g = rec.gauges
    t = g["t_ns"] / 1e9
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 7), constrained_layout=True)
    axes[0].plot(t, g["x_mm"], color="tab:gray", lw=0.9, label="measured x")
    if len(rec.command):
        axes[0].plot(
            t, rec.command_on_gauge_clock(), color="k", lw=0.7, ls="--", label="command x_cmd"
        )
        axes[0].legend(loc="center right")  # the run's end is at rest there
    axes[0].set_ylabel("drive x [mm]")
    axes[1].plot(t, g["u_mm"], color="tab:blue", lw=0.9)
    axes[1].set_ylabel("weight u [mm]")
    axes[2].plot(t, g["force_n"], color="tab:red", lw=0.7)
    axes[2].set_ylabel("fibre force F [N]")
    axes[2].set_xlabel("time since the start of the run [s]")
    lo, hi = (float(t[0]), float(t[-1])) if len(t) else (0.0, 1.0)
    for t_ns, kind, _ in rec.events_array.tolist():
        when = t_ns / 1e9
        if lo <= when <= hi:
            for ax in axes:
                ax.axvline(when, color=EVENT_COLOURS.get(kind, "0.6"), lw=0.8, ls=":")
            axes[0].annotate(
                kind, (when, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -3),
                textcoords="offset points", fontsize=8, rotation=90, va="top", ha="left",
            )  # fmt: skip
    gaps = np.flatnonzero(np.diff(g["seq"]) > 1) if len(g) > 1 else np.empty(0, int)
    for i in gaps:  # lost samples: the span between the samples on either side
        for ax in axes:
            ax.axvspan(t[i], t[i + 1], color="orange", alpha=0.3, lw=0)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    return cast("Figure", fig)
