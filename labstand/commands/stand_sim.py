"""``labstand stand-sim``: run the simulated stand on its own, and start it from Python.

The command serves the simulated Unidrive SP (Modbus TCP on 127.0.0.1 or RTU on a pty)
and the simulated gauge front end (2 kHz frames on a pty), prints where to connect —
with ``--json`` as one line ``{"event": "ready", "modbus": URL, "gauges": PATH, ...}`` —
and runs until Ctrl-C or SIGTERM, or until the process named by ``--parent-pid`` is
gone. On exit it prints ``{"event": "stopped", ...}`` and leaves nothing running.

``sim.hardware.process.StandProcess`` starts the command as a child process (how
``labstand run --backend sim`` uses it): it passes its own pid as ``--parent-pid``, so
the child exits within a fraction of a second even if the parent is killed with SIGKILL.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import os
import signal
import sys
from typing import TYPE_CHECKING, TextIO

from labstand.commands.common import add_stand_options, load_stand

if TYPE_CHECKING:  # pymodbus, numba: imported when the stand starts, not for --help
    from sim.hardware.stand import SimulatedStand

PARENT_POLL_S = 0.2
#: After its parent died, how long an enabled simulated drive may take to stop (its
#: watchdog trips within 1 s) before the process exits anyway, wall s.
ORPHAN_GRACE_S = 3.0
#: ... and how long it then goes on answering, so an observer can read why it stopped.
ORPHAN_LINGER_S = 1.0


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand stand-sim``."""
    parser = sub.add_parser(
        "stand-sim",
        description="Serve the simulated Unidrive SP over Modbus (TCP on 127.0.0.1, or RTU on "
        "a pseudo-terminal) and the simulated gauge front end on a pseudo-terminal, both "
        "driven by the stand model. Prints where to connect; stops on Ctrl-C or SIGTERM.",
    )
    add_stand_options(parser, params=True)
    parser.add_argument("--mass-kg", type=float, help="weight mass, kg (default: the stand's)")
    parser.add_argument(
        "--modbus",
        default="tcp://127.0.0.1:0",
        metavar="SPEC",
        help="tcp://127.0.0.1:PORT (0: any free port; the default), rtu (a pty pair of its "
        "own) or rtu:PATH (serve on an existing serial port)",
    )
    parser.add_argument(
        "--effect",
        action="append",
        default=[],
        metavar="NAME[:param=value,...]",
        help="switch an unmodelled effect on in the simulated stand, at default parameters "
        "or those given (repeatable; docs/effects.md)",
    )
    parser.add_argument(
        "--speed",
        type=float,
        default=1.0,
        help="simulated seconds per wall second (default 1: real time)",
    )
    parser.add_argument("--seed", type=int, default=0, help="gauge noise seed (default 0)")
    parser.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="KIND@T[:VALUE]",
        help="for tests: inject a fault T s after the drive starts a profile: trip, "
        "gauges-silent, garbage, modbus-mute (sim/hardware/faults.py; repeatable)",
    )
    parser.add_argument(
        "--foxglove",
        metavar="[HOST:]PORT",
        help="serve what the simulated gauges measure, and the baseline model beside it, "
        "to Foxglove on PORT (127.0.0.1 unless a HOST is given; docs/live-view.md)",
    )
    parser.add_argument("--json", action="store_true", help="print the endpoints as one JSON line")
    parser.add_argument(
        "--parent-pid",
        type=int,
        metavar="PID",
        help="exit when this process is gone (for programs that start the simulated stand)",
    )
    parser.set_defaults(func=run_stand_sim)


def _say(text: str, stream: TextIO | None = None) -> None:
    """Print and flush; a reader that went away (a dead parent's pipe) is not an error."""
    with contextlib.suppress(OSError):
        print(text, file=stream or sys.stdout, flush=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


async def _serve(stand: SimulatedStand, args: argparse.Namespace) -> None:
    endpoints = await stand.start()
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    info = endpoints.to_dict()
    if args.json:
        _say(json.dumps({"event": "ready", "pid": os.getpid(), **info}))
    else:
        _say(f"simulated stand (pid {os.getpid()}), {info['speed']:g}× real time")
        _say(f"  drive (Unidrive SP, Modbus): {info['modbus']}")
        rate, size = info["rate_hz"], info["frame_bytes"]
        _say(f"  gauges ({rate:g} Hz, {size}-byte frames): {info['gauges']}")
        _say("stop with Ctrl-C")

    async def watch_parent(pid: int) -> None:
        first_parent = os.getppid()
        while not stop.is_set():
            if not _alive(pid) or os.getppid() != first_parent:
                _say(f"labstand stand-sim: parent {pid} is gone; stopping", sys.stderr)
                # like the real drive, stop by the watchdog first (observable over Modbus)
                deadline = loop.time() + ORPHAN_GRACE_S
                if stand.drive.enabled:
                    while stand.drive.enabled and loop.time() < deadline:
                        await asyncio.sleep(0.05)
                    await asyncio.sleep(ORPHAN_LINGER_S)
                stop.set()
            await asyncio.sleep(PARENT_POLL_S)

    watcher = asyncio.create_task(watch_parent(args.parent_pid)) if args.parent_pid else None
    try:
        await stand.serve(stop)
    finally:
        if watcher is not None:
            watcher.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await watcher
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.remove_signal_handler(sig)
        await stand.close()


def run_stand_sim(args: argparse.Namespace) -> int:
    """Serve until stopped."""
    from sim.hardware.faults import parse_fault
    from sim.hardware.gauges import FrontEndSettings
    from sim.hardware.stand import ScaledClock, SimulatedStand, StandSettings

    config = load_stand(args)
    settings = StandSettings(
        modbus=args.modbus,
        effects=tuple(args.effect),
        faults=tuple(parse_fault(f) for f in args.fault),
        frontend=FrontEndSettings(rate_hz=config.sample_rate_hz, seed=args.seed),
    )
    stand = SimulatedStand.from_config(
        config, args.params, args.mass_kg, settings, ScaledClock(args.speed)
    )
    with contextlib.ExitStack() as stack:
        if args.foxglove is not None:
            from labstand.live.address import parse_address
            from labstand.live.standsim import FrontEndTap
            from labstand.live.view import LiveView

            params = config.stand_params(args.params, args.mass_kg)
            live = stack.enter_context(
                LiveView.open(
                    parse_address(args.foxglove),
                    "labstand stand-sim",
                    params,
                    settings.frontend.rate_hz,
                )
            )
            stand.frontend.tap = FrontEndTap(live.feed)
            # with --json, stdout carries only the JSON lines
            _say(f"live view: {live.describe()}", sys.stderr if args.json else None)
        try:
            asyncio.run(_serve(stand, args))
        finally:
            summary = stand.summary()
            if args.json:
                _say(json.dumps({"event": "stopped", **summary}))
    return 0
