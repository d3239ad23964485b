"""Figures a person looks at rather than reads."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:  # matplotlib is imported when a plot is drawn, not with this module
    from matplotlib.figure import Figure

    from recordings.replay import ReplayResult
    from sim.results import SimResult

_UNITS = {"u": "weight u [mm]", "F": "fibre force F [N]", "F_dyn": "dynamic force F − T₀ [N]"}
_RESIDUAL_UNITS = {"u": "Δu [mm]", "F": "ΔF [N]", "F_dyn": "Δ(F − T₀) [N]"}


def r_text(r: float) -> str:
    """R as the paper prints it: six decimals (0.999961); rounding to 4 would hide the gap."""
    return f"{r:.6f}"


def pyplot() -> ModuleType:
    """matplotlib.pyplot on the file-only backend: the CLI draws into files, never windows."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_run(path: Path, result: SimResult, title: str) -> None:
    """Drive position, weight displacement and fibre force over time, one panel each."""
    fig = run_figure(result, title)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)


def run_figure(result: SimResult, title: str) -> Figure:
    """The figure of ``plot_run``."""
    plt = pyplot()

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 7), constrained_layout=True)
    axes[0].plot(result.t_s, result.x_m * 1e3, color="tab:gray")
    axes[0].set_ylabel("drive x [mm]")
    axes[1].plot(result.t_s, result.u_m * 1e3, color="tab:blue")
    axes[1].set_ylabel("weight u [mm]")
    axes[2].plot(result.t_s, result.force_n, color="tab:red", lw=0.8)
    axes[2].axhline(result.preload_tension_n, color="k", lw=0.5, ls="--", label="rest tension")
    slack = result.slack
    if slack.any():
        axes[2].fill_between(
            result.t_s,
            0,
            result.force_n.max(),
            where=slack,
            color="orange",
            alpha=0.3,
            label="fibre slack",
        )
    axes[2].set_ylabel("fibre force F [N]")
    axes[2].set_xlabel("time [s]")
    axes[2].legend(loc="upper right")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    return cast("Figure", fig)  # pyplot() is a plain module to mypy


def plot_replay(
    path: Path,
    result: ReplayResult,
    title: str,
    second_label: str = "simulated",
    first_label: str = "recorded",
) -> None:
    """Recorded vs simulated u and F − T₀ (like the paper's figures), with the residuals."""
    fig = replay_figure(result, title, second_label, first_label)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)


def replay_figure(
    result: ReplayResult, title: str, second_label: str = "simulated", first_label: str = "recorded"
) -> Figure:
    """The figure of ``plot_replay``."""
    plt = pyplot()

    channels = ("u", "F_dyn")
    fig, axes = plt.subplots(
        4,
        1,
        sharex=True,
        figsize=(11, 9),
        constrained_layout=True,
        gridspec_kw={"height_ratios": [3, 1, 3, 1]},
    )
    t = result.t_s
    for k, name in enumerate(channels):
        ax, res_ax = axes[2 * k], axes[2 * k + 1]
        rec, sim = result.recorded[name], result.simulated[name]
        m = result.metrics[name]
        ax.plot(t, rec, color="k", lw=0.9, label=first_label)
        ax.plot(t, sim, color="tab:red", lw=0.9, ls="--", label=second_label)
        ax.set_ylabel(_UNITS[name])
        ax.set_title(
            f"{name}: R = {r_text(m.R)}, ψ = {m.psi:.3g}, NRMSE = {m.nrmse:.4f}", fontsize=10
        )
        ax.legend(loc="upper right", fontsize=9, framealpha=0.9)
        res_ax.plot(
            t, sim - rec, color="tab:purple", lw=0.7, label=f"{second_label} − {first_label}"
        )
        res_ax.axhline(0, color="k", lw=0.4)
        res_ax.set_ylabel(_RESIDUAL_UNITS[name])
        res_ax.legend(loc="best", fontsize=9, framealpha=0.9)
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    return cast("Figure", fig)  # pyplot() is a plain module to mypy
