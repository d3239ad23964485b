"""``labstand play``: a recording played to Foxglove, with the model beside it.

Serves the recording on a Foxglove WebSocket (the live run's topics: ``/gauges`` at
full rate, ``/command``, ``/drive``, ``/events``, ``/model``, ``/model/residual``) at real
time or ``--speed`` times, from ``--start`` s, once or ``--loop``. It waits for the first
client to subscribe (``--no-wait``: plays at once). Heavy modules (the SDK, the model)
are imported inside ``run``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from labstand.interrupts import Interrupt
    from labstand.live.address import ViewerAddress
    from recordings import Recording
    from sim.params import StandParams


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand play``."""
    parser = sub.add_parser(
        "play",
        help="play a recording to Foxglove (WebSocket), with the model beside it",
        description="Play a recording's gauges (every sample), command, drive polls and "
        "events to Foxglove over a WebSocket at real time (or --speed times), with the "
        "baseline model fed the recorded drive position and its residual "
        "(docs/live-view.md).",
    )
    parser.add_argument("recording", type=Path, help="recording (.mcap, .h5, .csv, .tdms)")
    parser.add_argument("--speed", type=float, default=1.0, help="times real time (default 1)")
    parser.add_argument(
        "--start", type=float, default=0.0, metavar="T", help="start T s into the recording"
    )
    parser.add_argument("--loop", action="store_true", help="play again and again (Ctrl-C)")
    parser.add_argument(
        "--foxglove",
        default="8765",
        metavar="[HOST:]PORT",
        help="where to serve: PORT on 127.0.0.1 unless a HOST is given (default 8765)",
    )
    parser.add_argument(
        "--no-wait", action="store_true", help="play at once, without waiting for a client"
    )
    parser.add_argument(
        "--params",
        default="final",
        help="the model's parameter set, or a stand FILE.toml (default: final)",
    )
    parser.add_argument("--stand", type=Path, metavar="FILE", help="stand file (default: stored)")
    parser.add_argument("--mass-kg", type=float, help="weight mass, kg (default: the recording's)")
    parser.set_defaults(func=run)


#: After the first subscription, how long other subscriptions may take to arrive, s.
SETTLE_S = 0.3


def run(args: argparse.Namespace) -> int:
    """Serve the recording until it ends (or Ctrl-C with --loop)."""
    from labstand.errors import CommandError, ExitCode
    from labstand.live.address import parse_address
    from labstand.recording_stand import params_for
    from recordings import open_recording

    if not args.speed > 0:
        raise CommandError(f"--speed must be > 0, got {args.speed:g}", ExitCode.USAGE)
    address = parse_address(args.foxglove)
    recording = open_recording(args.recording)
    params, name = params_for(recording, args.stand, args.params, args.mass_kg)
    if not 0 <= args.start < recording.duration_s:
        raise CommandError(
            f"--start {args.start:g} s is outside {args.recording} "
            f"(0 … {recording.duration_s:.3f} s)",
            ExitCode.USAGE,
        )
    from labstand.interrupts import remembered_interrupt

    with remembered_interrupt() as interrupted:
        return _serve(args, address, recording, params, name, interrupted)


def _serve(
    args: argparse.Namespace,
    address: ViewerAddress,
    recording: Recording,
    params: StandParams,
    name: str,
    interrupted: Interrupt,
) -> int:
    """Play once (or loop) to the clients of a server at ``address``."""
    import time

    from labstand.errors import ExitCode
    from labstand.live.player import Player, WallClock
    from labstand.live.server import LiveServer

    with LiveServer(address, f"labstand play {args.recording.name}") as server:
        player = Player(recording, server, params, WallClock(), args.speed, args.start)
        print(
            f"labstand play {args.recording}: {len(recording.gauges)} samples, "
            f"{recording.duration_s:.2f} s, model '{name}', {args.speed:g}× real time"
        )
        print(
            f"live view: {server.url} (Foxglove: Open connection → Foxglove WebSocket)", flush=True
        )
        if not args.no_wait:
            print("  waiting for a client to subscribe (Ctrl-C stops)", flush=True)
            server.wait_client()
            time.sleep(SETTLE_S)
        passes, end_ns = 0, 0
        while True:
            # each pass on the wall clock, after the last (at --speed > 1 the recording's
            # time runs ahead of the wall's)
            start_ns = max(time.time_ns(), end_ns + 1_000_000)
            server.epoch_ns = start_ns - player.start_ns
            end_ns = start_ns + player.span_ns
            stats = player.play(stop=interrupted.is_set)
            if interrupted.is_set():
                interrupted.raise_it()
            passes += 1
            print(
                f"  pass {passes}: {stats.samples} samples, {stats.drive} drive polls, "
                f"{stats.events} events",
                flush=True,
            )
            if not args.loop:
                break
    return ExitCode.OK
