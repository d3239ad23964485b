"""``labstand replay``: recordings' drive motion through the model, compared per channel."""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.distributed import add_cluster_options, run_many
from labstand.targets import FILE, check_output

if TYPE_CHECKING:  # imported where they run: `replay --help` loads no numba or pandas
    from sim.metrics import ChannelMetrics

LABEL = "labstand replay"


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
        "recordings",
        type=Path,
        nargs="+",
        metavar="REC",
        help="recording(s) (.mcap, .h5, .csv, .tdms); several are replayed in parallel on Dask",
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
    parser.add_argument(
        "--mass-kg",
        type=float,
        help="weight mass, kg (default: the --stand file's default weight, else the one "
        "stored in the recording)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON (channels.u.R, ...)")
    parser.add_argument(
        "--plot",
        type=Path,
        metavar="PNG",
        help="recorded vs simulated + residual; with several recordings one file each, "
        "named PNG's name + '-' + the recording's stem (--plot out/r.png: out/r-s11.png, ...)",
    )
    add_cluster_options(parser)
    parser.set_defaults(func=run, outputs={"plot": FILE})


@dataclass(frozen=True)
class ReplayJob:
    """One recording to replay (and where its plot goes, if anywhere)."""

    recording: Path
    params: str
    stand: Path | None
    mass_kg: float | None
    plot: Path | None = None


def replay_one(job: ReplayJob) -> dict[str, Any]:
    """The job: a recording's replay as JSON, its plot written (runs on a worker for many)."""
    from recordings import open_recording

    recording = open_recording(job.recording)  # refused before the model loads (numba: s)

    from labstand.recording_stand import mass_source, params_for
    from recordings.replay import replay

    params, name = params_for(recording, job.stand, job.params, job.mass_kg)
    result = replay(recording.frame(), params)
    out = {
        "recording": str(job.recording),
        "params": name,
        "mass_kg": params.mass_kg,
        "mass_source": mass_source(recording, job.stand, job.mass_kg),
        **result.to_dict(),
    }
    if job.plot is not None:
        from labstand.plots import plot_replay

        title = f"{job.recording.name}: replay with '{name}'"
        plot_replay(job.plot, result, title, second_label="simulated")
        out["plot"] = str(job.plot)
    return out


def plot_paths(plot: Path, recordings: Sequence[Path]) -> list[Path]:
    """Where each recording's plot goes: ``plot`` itself for one, else one per stem."""
    if len(recordings) == 1:
        return [plot]
    stems = [r.stem for r in recordings]
    # two recordings of one stem (a/s11.mcap, b/s11.mcap) are told apart by their position
    tags = [s if stems.count(s) == 1 else f"{s}-{i + 1}" for i, s in enumerate(stems)]
    return [plot.with_name(f"{plot.stem}-{tag}{plot.suffix}") for tag in tags]


def run(args: argparse.Namespace) -> int:
    """Replay each recording (several in parallel on Dask) and report."""
    plots = plot_paths(args.plot, args.recordings) if args.plot is not None else None
    for plot in plots or ():  # one per recording: each checked before any replay
        check_output(plot, args.force, option="--plot")
    jobs = [
        ReplayJob(p, args.params, args.stand, args.mass_kg, plots[i] if plots else None)
        for i, p in enumerate(args.recordings)
    ]
    outs, code = run_many(args, replay_one, jobs, [str(p) for p in args.recordings], LABEL)
    if args.json:
        print(json.dumps(outs[0] if len(jobs) == 1 and outs else outs, indent=2))
        return code
    for out in outs:
        print(f"Replay of {out['recording']} with parameters '{out['params']}', "
              f"m = {out['mass_kg']:g} kg ({out['mass_source']}):")  # fmt: skip
        print(f"  {'channel':8s} {'R':>10s} {'psi':>10s} {'NRMSE':>10s}")
        for name, m in out["channels"].items():
            print(f"  {name:8s} {m['R']:10.6f} {m['psi']:10.3g} {m['nrmse']:10.4f}")
        for note in out["notes"]:
            print(f"  note: {note}")
        if "plot" in out:
            print(f"  wrote {out['plot']}")
    return code


def metric_lines(metrics: Mapping[str, ChannelMetrics]) -> list[str]:
    """A small table of R, psi and NRMSE per channel."""
    lines = [f"  {'channel':8s} {'R':>10s} {'psi':>10s} {'NRMSE':>10s}"]
    lines += [f"  {n:8s} {m.R:10.6f} {m.psi:10.3g} {m.nrmse:10.4f}" for n, m in metrics.items()]
    return lines


def print_metrics(metrics: Mapping[str, ChannelMetrics]) -> None:
    """Print ``metric_lines``."""
    print("\n".join(metric_lines(metrics)))
