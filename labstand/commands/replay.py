"""``labstand replay``: recordings' drive motion through the model, compared per channel."""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sim.metrics import ChannelMetrics


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand replay``."""
    parser = sub.add_parser(
        "replay",
        description="Feed each recording's measured drive position into the baseline model "
        "and compare simulated with recorded u, F and F − T0 (R, psi = (1 − R)^2, NRMSE): "
        "one result per recording. --json prints one object for one recording, a list of "
        "them for several.",
    )
    parser.add_argument(
        "recordings", type=Path, nargs="+", metavar="REC", help="recordings (.mcap .h5 .csv .tdms)"
    )
    parser.add_argument(
        "--params",
        default="final",
        help="parameter set (starting, final, ...) or a stand FILE.toml whose 'final' set "
        "is used (default: final)",
    )
    parser.add_argument(
        "--stand",
        type=Path,
        metavar="FILE",
        help="stand file (default: the one stored in each recording)",
    )
    parser.add_argument("--mass-kg", type=float, help="weight mass, kg (default: the recording's)")
    parser.add_argument("--json", action="store_true", help="print JSON (channels.u.R, ...)")
    parser.add_argument(
        "--plot",
        type=Path,
        metavar="PNG",
        help="recorded vs simulated + residual; with several recordings one file each, "
        "named PNG's name + '-' + the recording's stem (--plot out/r.png: out/r-s11.png, ...)",
    )
    parser.set_defaults(func=run)


def plot_paths(plot: Path, recordings: Sequence[Path]) -> list[Path]:
    """Where each recording's plot goes: ``plot`` itself for one, else one per stem."""
    if len(recordings) == 1:
        return [plot]
    stems = [r.stem for r in recordings]
    # two recordings of one stem (a/s11.mcap, b/s11.mcap) are told apart by their position
    tags = [s if stems.count(s) == 1 else f"{s}-{i + 1}" for i, s in enumerate(stems)]
    return [plot.with_name(f"{plot.stem}-{tag}{plot.suffix}") for tag in tags]


def run(args: argparse.Namespace) -> int:
    """Replay each recording and report."""
    plots = plot_paths(args.plot, args.recordings) if args.plot is not None else None
    results = []
    for i, path in enumerate(args.recordings):
        out, text = replay_one(args, path, plots[i] if plots else None)
        results.append(out)
        if not args.json:
            print("\n".join(text), flush=True)
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=2))
    return 0


def replay_one(
    args: argparse.Namespace, path: Path, plot: Path | None
) -> tuple[dict[str, Any], list[str]]:
    """One recording's replay: its JSON object and its text block."""
    from labstand.plots import plot_replay
    from labstand.recording_stand import params_for
    from recordings import open_recording
    from recordings.replay import replay

    recording = open_recording(path)
    params, name = params_for(recording, args.stand, args.params, args.mass_kg)
    result = replay(recording.frame(), params)
    out: dict[str, Any] = {
        "recording": str(path),
        "params": name,
        "mass_kg": params.mass_kg,
        **result.to_dict(),
    }
    if plot is not None:
        plot_replay(plot, result, f"{path.name}: replay with '{name}'", second_label="simulated")
        out["plot"] = str(plot)
    text = [f"Replay of {path} with parameters '{name}', m = {params.mass_kg:g} kg:"]
    text += metric_lines(result.metrics)
    text += [f"  note: {note}" for note in result.notes]
    if plot is not None:
        text.append(f"  wrote {plot}")
    return out, text


def metric_lines(metrics: Mapping[str, ChannelMetrics]) -> list[str]:
    """A small table of R, psi and NRMSE per channel."""
    lines = [f"  {'channel':8s} {'R':>10s} {'psi':>10s} {'NRMSE':>10s}"]
    lines += [f"  {n:8s} {m.R:10.6f} {m.psi:10.3g} {m.nrmse:10.4f}" for n, m in metrics.items()]
    return lines


def print_metrics(metrics: Mapping[str, ChannelMetrics]) -> None:
    """Print ``metric_lines``."""
    print("\n".join(metric_lines(metrics)))
