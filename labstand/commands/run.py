"""``labstand run``: run a test on the stand (or the simulated stand) and record it.

Pre-flight (configuration, devices, drive health, limits; refused → exit 3, nothing
moved), a summary and — at the stand, unless ``--yes`` — a confirmation, then the run
under ``labstand.session.Session`` with a live display. Exit codes: 0 done, 3 refused,
4 emergency stop, 130 Ctrl-C (first: controlled stop; second: immediate disable), 1 a
device failed before the run. Every path leaves the drive disabled and the recording
closed.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from drivers.signals import SignalSpec, plan_motion
from labstand.commands.common import (
    add_metadata_options,
    add_stand_options,
    config_with_mass,
    load_stand,
    metadata_options,
)
from labstand.commands.simulate import add_signal_options, signal_from_args
from labstand.errors import CommandError, ExitCode
from labstand.interrupts import stop_presses
from labstand.live.address import ViewerAddress, parse_address
from labstand.prediction import Verdict, add_prediction_options, check_motion, fitted_from_args
from labstand.session import (
    Outcome,
    Preflight,
    PreflightError,
    RunResult,
    Session,
    StopRequest,
)
from labstand.session.display import make_display
from labstand.session.record import RecordingPipe
from labstand.session.safety import EStopError, SafetyLimits
from labstand.targets import FILE
from recordings.base import open_writer
from recordings.schema import Effect, RecordingMetadata, make_metadata

if TYPE_CHECKING:  # imported where they run: `labstand run --help` loads no numba
    from labstand.live.view import LiveView
    from labstand.session.devices import Devices
    from sim.config import StandConfig
    from sim.effects import EffectSpec


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand run``."""
    parser = sub.add_parser(
        "run",
        description="Run a drive signal on the stand and record gauges (2 kHz), drive "
        "states and events to -o OUT (.mcap or .h5). --backend sim starts the simulated "
        "stand (same wire protocols) and is the default when the stand file has no "
        "[devices] table. Ctrl-C once: controlled stop; twice: drive disabled at once.",
    )
    add_signal_options(parser)
    add_stand_options(parser)
    parser.add_argument(
        "--backend",
        metavar="NAME",
        help="stand: the devices of the stand file's [devices]; sim: the simulated stand "
        "(default: stand if the stand file has [devices], else sim); any other backend of "
        "the registry (labstand.session.devices.BACKENDS)",
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="recording (.mcap, .h5)")
    parser.add_argument("--note", default="", help="operator note, stored in the recording")
    add_metadata_options(parser)
    parser.add_argument("--yes", action="store_true", help="start without asking (stand)")
    parser.add_argument(
        "--reset-trip", action="store_true", help="reset a tripped drive during pre-flight"
    )
    parser.add_argument(
        "--effect",
        action="append",
        default=[],
        metavar="NAME[:param=value,...]",
        help="sim: switch an unmodelled effect on in the simulated stand, at default "
        "parameters or those given (repeatable; docs/effects.md)",
    )
    add_prediction_options(parser, override=True)
    safety = parser.add_argument_group("emergency-stop thresholds (docs/acquisition.md)")
    defaults = SafetyLimits()
    for name, unit, what in (
        ("position_margin_mm", "mm", "x allowed beyond the planned 0 … A"),
        ("slack_force_n", "N", "below it the fibre counts as slack"),
        ("slack_max_s", "s", "longest slack while the drive runs"),
        ("gauge_timeout_s", "s", "longest gauge silence"),
    ):
        safety.add_argument(
            "--" + name.replace("_", "-"),
            type=float,
            default=getattr(defaults, name),
            help=f"{what}, {unit} (default {getattr(defaults, name):g})",
        )
    parser.add_argument(
        "--foxglove",
        metavar="[HOST:]PORT",
        help="serve the run live to Foxglove (WebSocket) on PORT, on 127.0.0.1 unless a "
        "HOST is given (docs/live-view.md); 0 picks a free port",
    )
    # for tests: faults injected by the simulated stand (sim/hardware/faults.py)
    parser.add_argument("--sim-fault", action="append", default=[], help=argparse.SUPPRESS)
    parser.set_defaults(func=run, outputs={"output": FILE})


def _title(args: argparse.Namespace, spec: SignalSpec, mass_kg: float) -> str:
    what = f"situation {args.situation}: " if args.situation else ""
    return (
        f"{what}{spec.shape} A = {spec.amplitude_m * 1e3:g} mm, f = {spec.frequency_hz:g} Hz, "
        f"{spec.cycles} cycle(s), m = {mass_kg:g} kg"
    )


def _effects(args: argparse.Namespace, backend: str) -> list[EffectSpec]:

    from sim.effects import parse_effects

    effects = parse_effects(args.effect)
    if effects and backend != "sim":
        raise CommandError("--effect needs --backend sim", ExitCode.USAGE)
    return effects


@dataclass(frozen=True)
class _Plan:
    """What the arguments ask for, checked before any device is opened."""

    config: StandConfig
    spec: SignalSpec
    mass_kg: float
    backend: str
    effects: list[EffectSpec]
    safety: SafetyLimits
    confirm: bool
    viewer: ViewerAddress | None
    verdict: Verdict


def _check(args: argparse.Namespace) -> _Plan:
    """Every check that needs no device: usage (2) and refusals (3)."""
    from recordings.formats import suffixes

    config = load_stand(args)
    spec, mass = signal_from_args(args, config)
    if not (math.isfinite(mass) and mass > 0):  # before the simulated stand starts with it
        raise CommandError(f"--mass-kg: mass must be > 0 kg, got {mass:g} kg", ExitCode.USAGE)
    from labstand.session.devices import BACKENDS, default_backend

    backend = args.backend or default_backend(config)
    if backend not in BACKENDS:  # checked here, not by argparse: the registry pulls scipy
        raise CommandError(
            f"--backend: unknown backend {backend!r} (known: {', '.join(BACKENDS)})",
            ExitCode.USAGE,
        )
    if backend == "stand" and config.devices is None:
        raise CommandError(
            f"{config.source}: no [devices] table, so no stand to run; add one "
            "(docs/configuration.md) or use --backend sim",
            ExitCode.USAGE,
        )
    effects = _effects(args, backend)
    safety = SafetyLimits(
        position_margin_mm=args.position_margin_mm,
        slack_force_n=args.slack_force_n,
        slack_max_s=args.slack_max_s,
        gauge_timeout_s=args.gauge_timeout_s,
    )
    profile = plan_motion(spec, config.drive)  # LimitError: refused before anything is touched
    suffix = args.output.suffix.lower()
    if suffix not in (writable := suffixes("write")):
        raise CommandError(
            f"{args.output}: cannot record {suffix or 'without a suffix'!r}; use one of "
            f"{', '.join(writable)}",
            ExitCode.USAGE,
        )
    confirm = backend == "stand" and not args.yes
    if confirm and not sys.stdin.isatty():
        raise CommandError(
            "at the stand a run must be confirmed, and there is no terminal to ask on: give --yes",
            ExitCode.REFUSED,
        )
    viewer = parse_address(args.foxglove) if args.foxglove is not None else None
    fitted = fitted_from_args(args)
    verdict = check_motion(config, profile, mass, safety, fitted, args.override_prediction)
    return _Plan(config, spec, mass, backend, effects, safety, confirm, viewer, verdict)


def run(args: argparse.Namespace) -> int:
    """Check, confirm, run, report."""
    if not args.verbose:  # the device layer's retries and warnings: the log (-v), not the
        # terminal, where the run's end is one line that says what failed
        for name in ("pymodbus", "drivers", "sim.hardware"):
            logging.getLogger(name).setLevel(logging.CRITICAL)
    plan = _check(args)
    with contextlib.ExitStack() as stack:
        live = None
        if plan.viewer is not None:  # before any device: a busy port is bad input (2)
            from labstand.live.view import LiveView

            params = plan.config.stand_params("final", plan.mass_kg)
            live = stack.enter_context(
                LiveView.open(plan.viewer, "labstand run", params, plan.config.sample_rate_hz)
            )
            _say(f"live view: {live.describe()}")
        return _run_devices(args, plan, live)


def _run_devices(args: argparse.Namespace, plan: _Plan, live: LiveView | None) -> int:
    """Open the devices, run the session, report."""
    from labstand.session.devices import open_devices

    devices = open_devices(
        plan.backend,
        plan.config,
        mass_kg=plan.mass_kg,
        stand_file=args.stand,
        effects=tuple(str(e) for e in plan.effects),
        sim_args=tuple(a for f in args.sim_fault for a in ("--fault", f)),
    )
    try:
        title = _title(args, plan.spec, plan.mass_kg)
        _say(f"labstand run: {title}")
        _say(f"  {plan.backend}: {devices.where}")
        if getattr(args, "stand_origin", ""):
            _say(f"  stand file: {args.stand} (from {args.stand_origin})")
        display = make_display(sys.stdout)
        if live is not None:
            display = live.display(display)
        session = Session(devices.drive, devices.gauges, plan.safety, display)
        try:
            result = _session(session, devices, plan, args, title, live)
        finally:
            session.shutdown()
    finally:
        devices.close()
    if live is not None:
        live.feed.close()  # publish what is queued, so the counts are final
        _say(f"  live view: {live.feed.published} samples published, {live.feed.summary()}")
    return _report(result, args.output, devices.sim_summary)


def _session(
    session: Session,
    devices: Devices,
    plan: _Plan,
    args: argparse.Namespace,
    title: str,
    live: LiveView | None,
) -> RunResult:
    """Pre-flight, summary, confirmation, prepare, then the recorded run."""
    from labstand.session import StopRequest

    try:
        pre = session.preflight(plan.spec, args.reset_trip)
    except PreflightError as err:
        code = ExitCode.REFUSED if err.refused else ExitCode.FAILURE
        raise CommandError(f"pre-flight: {err}", code) from err
    _summary(session, pre, args.output)
    _say(f"  prediction: {plan.verdict.line()}")
    if plan.confirm:
        with session.keepalive():
            _confirm()
    stop = StopRequest()
    with stop_presses(stop):
        try:
            session.prepare(pre, stop)
        except EStopError as err:
            session.shutdown()
            code = _stop_code(stop.by) if stop.presses else ExitCode.ESTOP
            drive = "drive disabled" if session.drive_disabled else "the drive did not answer"
            raise CommandError(f"{err}; {drive}; nothing recorded", code) from err
        metadata = make_metadata(
            config_with_mass(plan.config, plan.mass_kg),
            devices.backend,
            sample_rate_hz=plan.config.sample_rate_hz,
            signal={**plan.spec.to_dict(), "situation": args.situation},
            effects=tuple(Effect(e.name, e.resolved()) for e in plan.effects),
            operator_note=args.note,
            **metadata_options(args, plan.verdict.tags),
        )
        return _record(session, devices, metadata, args, stop, title, live, plan.verdict)


def _record(
    session: Session,
    devices: Devices,
    metadata: RecordingMetadata,
    args: argparse.Namespace,
    stop: StopRequest,
    title: str,
    live: LiveView | None,
    verdict: Verdict,
) -> RunResult:
    """The run itself, recording into the output; the file is closed on every path."""
    writer = open_writer(args.output, metadata)
    pipe = RecordingPipe(writer) if live is None else live.pipe(writer)
    try:
        if args.note:
            pipe.put_event(0, "note", args.note)
        if verdict.overridden:
            pipe.put_event(0, "note", verdict.override_note())
        with session.display:
            return session.run(pipe, stop, title)
    finally:
        try:
            session.shutdown()
            final = devices.stop_sim()
            if final:
                state = "enabled" if final.get("enabled") else "disabled"
                pipe.put_event(
                    session.clock.host_ns(time.monotonic()),
                    "note",
                    f"simulated stand stopped: drive {state}, "
                    f"x = {final.get('x_mm', float('nan')):.2f} mm, trips {final.get('trips')}",
                )
        finally:
            pipe.close()


def _say(text: str) -> None:
    print(text, flush=True)


def _summary(session: Session, pre: Preflight, output: Path) -> None:
    st, limits, p = pre.state, session.drive.limits, pre.profile
    _say(
        f"  drive: healthy, x = {st.position_m * 1e3:.2f} mm"
        + (" (moves home first)" if pre.needs_home else "")
        + f"; gauges: F = {pre.force_n:.1f} N, u = {pre.u_mm:.2f} mm at rest"
    )
    _say(
        f"  motion: {p.duration_s:.2f} s, peak {p.peak_speed_m_s:.3g} m/s, "
        f"{p.peak_accel_m_s2:.3g} m/s² (drive limits {limits.speed_max_m_s:g} m/s, "
        f"{limits.accel_max_m_s2:g} m/s²)"
    )
    _say(f"  safety: {session.monitor.describe()}")
    _say(f"  recording: {output}")


def _confirm() -> None:
    answer = input("Start the run? The drive will move. [y/N] ").strip().lower()
    if answer not in {"y", "yes"}:
        raise CommandError("not confirmed; nothing moved", ExitCode.REFUSED)


def _report(result: RunResult, output: Path, sim: dict[str, Any]) -> int:

    stats = result.stats
    where = (
        f"recording {output} closed ({result.elapsed_s:.2f} s, {result.samples} samples, "
        f"{stats.lost} lost, {stats.corrupt} corrupt)"
    )
    if result.drive_disabled:
        drive = "drive disabled"
    else:
        drive = "the drive did not acknowledge the disable"
        if sim:
            state = "disabled" if not sim.get("enabled") else "STILL ENABLED"
            drive += f"; the simulated drive reports itself {state}, trips {sim.get('trips')}"
        else:
            drive += "; its watchdog stops it within 1 s"
    if result.outcome is Outcome.DONE:
        _say(f"Done: {drive}; {where}")
        return ExitCode.OK
    by = result.reason.split(" ", 1)[0]  # "SIGTERM at 1.20 s: controlled stop"
    code = _stop_code(by) if result.outcome is Outcome.STOPPED else ExitCode.ESTOP
    raise CommandError(f"{result.reason}; {drive}; {where}", code)


def _stop_code(by: str) -> ExitCode:
    """130 for Ctrl-C, 143 for SIGTERM: the signal named as it came."""
    return ExitCode.TERMINATED if by == "SIGTERM" else ExitCode.INTERRUPTED
