"""The report's plots over time: residuals, the zoomed overlay, and the remainder's fit."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from labstand.plots import pyplot
from sim.identify import Diagnosis, Trace
from sim.identify.signature import Signature
from sim.identify.traces import PHASES

__all__ = ["balance_plot", "overlay_plot", "remainder_plot", "residual_plot"]

PHASE_COLOURS = {"rise": "tab:red", "hold": "tab:orange", "fall": "tab:blue", "rest": "tab:gray"}
#: A recording's name in a panel title, at most this many characters (the title stays
#: inside the image however long the file name).
TITLE_NAME = 36


def short_name(name: str, width: int = TITLE_NAME) -> str:
    """``name``, its middle elided to fit ``width`` characters."""
    if len(name) <= width:
        return name
    keep = width - 1
    return f"{name[: keep - keep // 2]}…{name[-(keep // 2) :]}"


def residual_plot(path: Path, traces: Sequence[Trace], result: Diagnosis) -> None:
    """The fitted baseline's residual per recording and channel, coloured by phase."""
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
            ax.set_title(f"{short_name(tr.name)}: fitted baseline − recorded", fontsize=10,
                         loc="left")  # fmt: skip
            ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncol=5, markerscale=12, fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)


#: Width of the zoomed window around the largest residual, s: narrow enough that a gap of
#: a few tenths of a millimetre on a 30 mm stroke is visible at the window's own scale.
ZOOM_S = 0.12
#: Colours shared by every panel (one legend for the figure).
RECORDED, BASELINE, AUGMENTED = "k", "tab:blue", "tab:red"


def overlay_plot(path: Path, traces: Sequence[Trace], result: Diagnosis) -> None:
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
                f"{short_name(tr.name)}: {name}, model − recorded (shaded: zoomed on the right)",
                fontsize=10,
                loc="left",
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
                f"largest miss {res_b[k]:+.3g} {unit}, t = {t[k]:.3f} s", fontsize=10, loc="left"
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


def remainder_plot(path: Path, traces: Sequence[Trace], result: Diagnosis) -> bool:
    """The final model's remainder against what its best signature predicts (False: none).

    Per recording, each channel the signature acts in: the remainder (recorded − model)
    in grey, the signature's fit in colour, held-out cycles shaded; where the best is the
    balances', the balance it acts in instead (``balance_plot``).
    """
    rem = result.remainder
    passing = [s for s in rem.signature if s.passes] if rem is not None else []
    if rem is None or not passing:
        return False
    if passing[0].source == "balances" and balance_plot(path, passing[0]):
        return True  # the answer's kind came from the balances: the force it describes
    # The model's outputs' signatures: the balances' describe forces, not these channels.
    passing = [s for s in passing if s.source == "outputs"]
    if not passing:
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
            ax.set_title(short_name(tr.name), fontsize=10, loc="left")
            ax.grid(alpha=0.3)
            row += 1
    axes[-1, 0].set_xlabel("time [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncol=3, fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


#: The balance's running mean in the plot, s: the noise above the low-pass averaged out.
SMOOTH_S = 0.1


def _running_mean(values: np.ndarray, where: np.ndarray, width: int) -> np.ndarray:
    """Mean of ``values`` over ``width`` samples, counting only ``where``; NaN outside it."""
    kernel = np.ones(max(width, 1))
    total = np.convolve(np.where(where, values, 0.0), kernel, mode="same")
    count = np.convolve(where.astype(float), kernel, mode="same")
    mean = total / np.maximum(count, 1.0)
    return np.where(where & (count > 0.5 * kernel.size), mean, np.nan)


#: The two balances as the plot names them: (series, its term, where it holds, label).
_BALANCES = (
    ("tension", "tension_term", "taut", "missing tension [N]"),
    ("weight", "weight_term", "sliding", "missing force on the weight [N]"),
)


def balance_plot(path: Path, signature: Signature) -> bool:
    """A balances' signature: per recording, the balance it acts in against its fit.

    Grey: the balance (the recorded one less the model's own, less the baseline's own
    terms) where it holds; colour: the signature's terms; held-out cycles shaded.
    False (nothing drawn) where its terms vanish wherever a balance holds.
    """
    rows = []
    for part in signature.series:
        for series, term, held, label in _BALANCES:
            if np.any(getattr(part, term)[getattr(part, held)] != 0.0):
                rows.append((part, series, term, held, label))
    if not rows:
        return False
    plt = pyplot()
    fig, axes = plt.subplots(
        len(rows), 1, figsize=(11, 2.4 * len(rows) + 0.8), squeeze=False, layout="constrained"
    )
    for ax, (part, series, term, held, label) in zip(axes[:, 0], rows, strict=True):
        t = np.arange(part.train.size) / part.rate_hz
        where = getattr(part, held)
        values = getattr(part, series)
        ax.plot(t, np.where(where, values, np.nan), color="0.6", lw=0.5,
                label="balance (recorded − model)")  # fmt: skip
        ax.plot(t, _running_mean(values, where, int(SMOOTH_S * part.rate_hz)), color="k",
                lw=0.8, label=f"its mean over {SMOOTH_S * 1e3:.0f} ms")  # fmt: skip
        ax.plot(t, np.where(where, getattr(part, term), np.nan), color="tab:red", lw=1.0,
                label=f"{signature.kind} term")  # fmt: skip
        low, high = ax.get_ylim()
        ax.fill_between(t, low, high, where=~part.train, color="k", alpha=0.06,
                        label="held out")  # fmt: skip
        ax.set_ylim(low, high)
        ax.set_ylabel(label, fontsize=9)
        ax.set_title(short_name(part.name), fontsize=10, loc="left")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.suptitle(f"{signature.kind} in {signature.channel}, from the balances: "
                 f"{short_name(signature.formula, 110)}", fontsize=10)  # fmt: skip
    fig.legend(handles, labels, loc="outside lower center", ncol=4, fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True
