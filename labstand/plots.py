"""Figures a person looks at rather than reads."""

from __future__ import annotations

from pathlib import Path

from sim.model import SimResult


def plot_run(path: Path, result: SimResult, title: str) -> None:
    """Drive position, weight displacement and fibre force over time, one panel each."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
    fig.savefig(path, dpi=110)
    plt.close(fig)
