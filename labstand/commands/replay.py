"""``labstand replay``: recordings' drive motion through the model, compared per channel."""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from labstand.distributed import add_cluster_options, run_many
from labstand.errors import CommandError, ExitCode

if TYPE_CHECKING:  # imported where they run: `replay --help` loads no numba or pandas
    from recordings.replay import ReplayResult
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
    parser.add_argument("--plot", type=Path, metavar="PNG", help="recorded vs simulated + residual")
    add_cluster_options(parser)
    parser.set_defaults(func=run)


@dataclass(frozen=True)
class ReplayJob:
    """One recording to replay."""

    recording: Path
    params: str
    stand: Path | None
    mass_kg: float | None


def _replayed(job: ReplayJob) -> tuple[dict[str, Any], ReplayResult]:
    from labstand.recording_stand import mass_source, params_for
    from recordings import open_recording
    from recordings.replay import replay

    recording = open_recording(job.recording)
    params, name = params_for(recording, job.stand, job.params, job.mass_kg)
    result = replay(recording.frame(), params)
    out = {
        "recording": str(job.recording),
        "params": name,
        "mass_kg": params.mass_kg,
        "mass_source": mass_source(recording, job.stand, job.mass_kg),
        **result.to_dict(),
    }
    return out, result


def replay_one(job: ReplayJob) -> dict[str, Any]:
    """The job: a recording's replay as JSON (runs on a worker for several recordings)."""
    return _replayed(job)[0]


def run_several(args: argparse.Namespace) -> int:
    """Replay several recordings (JSON: a list, one object per recording)."""
    if args.plot is not None:
        raise CommandError("--plot takes one recording", ExitCode.USAGE)
    jobs = [ReplayJob(p, args.params, args.stand, args.mass_kg) for p in args.recordings]
    outs, code = run_many(args, replay_one, jobs, [str(p) for p in args.recordings], LABEL)
    if args.json:
        print(json.dumps(outs, indent=2))
        return code
    for out in outs:
        print(f"Replay of {out['recording']} with parameters '{out['params']}', "
              f"m = {out['mass_kg']:g} kg ({out['mass_source']}):")  # fmt: skip
        print(f"  {'channel':8s} {'R':>10s} {'psi':>10s} {'NRMSE':>10s}")
        for name, m in out["channels"].items():
            print(f"  {name:8s} {m['R']:10.6f} {m['psi']:10.3g} {m['nrmse']:10.4f}")
        for note in out["notes"]:
            print(f"  note: {note}")
    return code


def run(args: argparse.Namespace) -> int:
    """Replay and report."""
    if len(args.recordings) > 1 or args.scheduler is not None or args.workers is not None:
        return run_several(args)
    args.recording = args.recordings[0]
    out, result = _replayed(ReplayJob(args.recording, args.params, args.stand, args.mass_kg))
    name = out["params"]
    if args.plot is not None:
        from labstand.plots import plot_replay

        plot_replay(
            args.plot,
            result,
            f"{args.recording.name}: replay with '{name}'",
            second_label="simulated",
        )
        out["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(
        f"Replay of {args.recording} with parameters '{name}', "
        f"m = {out['mass_kg']:g} kg ({out['mass_source']}):"
    )
    print_metrics(result.metrics)
    for note in result.notes:
        print(f"  note: {note}")
    if args.plot is not None:
        print(f"  wrote {args.plot}")
    return 0


def metric_lines(metrics: Mapping[str, ChannelMetrics]) -> list[str]:
    """A small table of R, psi and NRMSE per channel."""
    lines = [f"  {'channel':8s} {'R':>10s} {'psi':>10s} {'NRMSE':>10s}"]
    lines += [f"  {n:8s} {m.R:10.6f} {m.psi:10.3g} {m.nrmse:10.4f}" for n, m in metrics.items()]
    return lines


def print_metrics(metrics: Mapping[str, ChannelMetrics]) -> None:
    """Print ``metric_lines``."""
    print("\n".join(metric_lines(metrics)))
