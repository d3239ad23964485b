"""``labstand simulate``: run the baseline model on a paper situation or any signal."""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

# Light (numpy only): the parser's choices. The model (numba, scipy) is imported in run().
from drivers.signals import DriveProfile, Shape, SignalSpec, plan_motion
from labstand.commands.common import (
    add_metadata_options,
    add_stand_options,
    load_stand,
    metadata_options,
)
from labstand.errors import CommandError, ExitCode
from labstand.prediction import add_prediction_options, fitted_from_args
from labstand.targets import FILE
from sim.situations import SITUATIONS, situation

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from labstand.prediction import Verdict
    from sim.config import StandConfig
    from sim.effects import EffectSpec
    from sim.envelope import SlackRule
    from sim.params import StandParams
    from sim.results import SimResult


def add_signal_options(parser: argparse.ArgumentParser) -> None:
    """The drive-signal options shared by simulate and run."""
    group = parser.add_argument_group("drive signal")
    group.add_argument("--situation", choices=list(SITUATIONS), help="a paper situation preset")
    group.add_argument("--signal", choices=[s.value for s in Shape], help="signal shape")
    group.add_argument("--amplitude-mm", type=float, help="stroke A, mm (≤ the drive limit)")
    group.add_argument("--frequency-hz", type=float, help="cycle rate f, Hz")
    group.add_argument("--cycles", type=int, help="number of cycles (default 3)")
    group.add_argument(
        "--ramp-fraction", type=float, help="trapezoidal: ramp time / period (default 0.25)"
    )
    group.add_argument("--dwell-start-s", type=float, help="rest before the motion, s (0.5)")
    group.add_argument("--dwell-end-s", type=float, help="rest after the motion, s (1.0)")
    group.add_argument("--mass-kg", type=float, help="weight mass, kg (default: the stand's)")
    group.add_argument(
        "--plan",
        type=Path,
        metavar="PLAN.json",
        help="the motion and weight a `labstand plan -o PLAN.json` chose (no other signal "
        "option beside it)",
    )


def signal_from_args(args: argparse.Namespace, config: StandConfig) -> tuple[SignalSpec, float]:
    """The signal and weight mass the options ask for (a plan, or a situation and overrides)."""
    if args.plan is not None:
        from labstand.planning import PLAN_OPTIONS, signal_from_plan

        given = [f"--{o.replace('_', '-')}" for o in PLAN_OPTIONS if getattr(args, o) is not None]
        return signal_from_plan(args.plan, given)
    overrides: dict[str, Any] = {}
    if args.amplitude_mm is not None:
        overrides["amplitude_m"] = args.amplitude_mm / 1e3
    for name in ("frequency_hz", "cycles", "ramp_fraction", "dwell_start_s", "dwell_end_s"):
        if getattr(args, name) is not None:
            overrides[name] = getattr(args, name)
    if args.situation is not None:
        preset = situation(args.situation)
        spec = preset.signal
        if args.signal is not None:
            overrides["shape"] = Shape(args.signal)
        spec = SignalSpec(**{**spec.__dict__, **overrides})
        mass = preset.mass_kg
    else:
        if args.signal is None:
            raise CommandError("give --situation NAME or --signal SHAPE", ExitCode.USAGE)
        missing = [
            o
            for o, k in (("--amplitude-mm", "amplitude_m"), ("--frequency-hz", "frequency_hz"))
            if k not in overrides
        ]
        if missing:
            raise CommandError(f"--signal needs {' and '.join(missing)}", ExitCode.USAGE)
        overrides.setdefault("cycles", 3)
        spec = SignalSpec(shape=Shape(args.signal), **overrides)
        mass = config.default_mass_kg
    if args.mass_kg is not None:
        mass = args.mass_kg
    if not (math.isfinite(mass) and mass > 0):  # before any stand starts
        raise CommandError(f"--mass-kg: mass must be > 0 kg, got {mass:g}", ExitCode.USAGE)
    return spec, mass


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand simulate``."""
    parser = sub.add_parser(
        "simulate",
        description="Simulate the stand for a paper situation (--situation) or any drive "
        "signal (--signal ...). Writes the run to -o OUT (format by suffix).",
    )
    add_signal_options(parser)
    add_stand_options(parser, params=True)
    parser.add_argument("-o", "--output", type=Path, help="write the run here (.csv, ...)")
    parser.add_argument("--plot", type=Path, metavar="PNG", help="plot x, u and F to a PNG")
    add_metadata_options(parser)
    add_prediction_options(parser, override=False)
    parser.add_argument("--json", action="store_true", help="print a JSON summary")
    effects = parser.add_argument_group("unmodelled effects (docs/effects.md)")
    effects.add_argument(
        "--effect",
        action="append",
        metavar="NAME[:param=value,...]",
        help="switch an effect on (repeatable); see `labstand model effects`",
    )
    effects.add_argument(
        "--noise", action="store_true", help="add realistic gauge noise, mains hum, quantisation"
    )
    effects.add_argument("--seed", type=int, default=0, help="seed of --noise (default 0)")
    parser.set_defaults(func=run, outputs={"output": FILE, "plot": FILE})


def summarise(result: SimResult, profile: DriveProfile, mass_kg: float) -> dict[str, Any]:
    """A few numbers a person checks first."""
    slack = result.slack
    return {
        "duration_s": float(result.t_s[-1]),
        "samples": int(result.t_s.shape[0]),
        "mass_kg": mass_kg,
        "signal": profile.spec.to_dict(),
        "peak_drive_speed_m_s": profile.peak_speed_m_s,
        "u_min_mm": float(result.u_m.min() * 1e3),
        "u_max_mm": float(result.u_m.max() * 1e3),
        "force_max_n": float(result.force_n.max()),
        "preload_tension_n": result.preload_tension_n,
        "slack_fraction": float(slack.mean()),
        "slack_episodes": int(np.count_nonzero(np.diff(slack.astype(np.int8)) == 1)),
    }


def run(args: argparse.Namespace) -> int:
    """Simulate, write, summarise."""
    from labstand.output import write_simulation
    from sim.effects import parse_effects
    from sim.model import Model

    config = load_stand(args)
    spec, mass = signal_from_args(args, config)
    profile = plan_motion(spec, config.drive)
    params = config.stand_params(args.params, mass)
    _, x_m = profile.sample(config.sample_rate_hz)
    effects = parse_effects(args.effect or [])
    verdict = _prediction(args, config, profile, mass)
    started = time.perf_counter()
    if effects or args.noise:
        result, truth = _simulate_real_like(x_m, config.sample_rate_hz, params, effects, args)
    else:
        result = truth = Model(params).run(x_m, config.sample_rate_hz)
    elapsed = time.perf_counter() - started
    summary = summarise(truth, profile, mass)
    if effects or args.noise:
        summary["effects"] = [str(e) for e in effects]
        summary["noise_seed"] = args.seed if args.noise else None
    summary["params"] = args.params
    summary["situation"] = args.situation
    summary["wall_s"] = elapsed
    summary["prediction"] = {
        "admissible": verdict.admissible,
        "breaches": verdict.breaches,
        "model": verdict.model,
        **verdict.prediction.to_dict(config.envelope, _slack_rule()),
    }
    if args.output is not None:
        write_simulation(
            args.output,
            result,
            config,
            args.params,
            profile,
            args.situation,
            mass,
            **metadata_options(args),
        )
        summary["output"] = str(args.output)
    if args.plot is not None:
        from labstand.plots import plot_run

        plot_run(args.plot, result, title=_title(args, spec, mass))
        summary["plot"] = str(args.plot)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        _print_summary(summary)
    return 0


def _slack_rule() -> SlackRule:
    """The slack e-stop rule of a run at the default thresholds."""
    from labstand.session.safety import SafetyLimits
    from sim.envelope import SlackRule

    limits = SafetyLimits()
    return SlackRule(limits.slack_force_n, limits.slack_max_s)


def _prediction(
    args: argparse.Namespace, config: StandConfig, profile: DriveProfile, mass_kg: float
) -> Verdict:
    """What ``run`` would predict for this motion; a warning on stderr where it would refuse."""
    from labstand.prediction import predict_profile, warn_simulated

    verdict = predict_profile(config, profile, mass_kg, _slack_rule(), fitted_from_args(args))
    warn_simulated(verdict)
    return verdict


def _simulate_real_like(
    x_m: NDArray[np.float64],
    rate_hz: float,
    params: StandParams,
    effects: list[EffectSpec],
    args: argparse.Namespace,
) -> tuple[SimResult, SimResult]:
    """The augmented model with --effect, then --noise (seeded by --seed).

    Returns the recorded-like run and the true one (for the summary's slack figures).
    """
    from sim.effects.realism import NoiseSpec, add_measurement_noise
    from sim.model import Model

    run = Model(params, effects).run(x_m, rate_hz)
    truth = replace(run, u_m=run.true_u_m, force_n=run.true_force_n)
    result: SimResult = run
    if args.noise:
        result = add_measurement_noise(run, np.random.default_rng(args.seed), NoiseSpec())
    return result, truth


def _title(args: argparse.Namespace, spec: SignalSpec, mass: float) -> str:
    what = f"situation {args.situation}" if args.situation else str(spec.shape)
    return (
        f"{what}: {spec.shape}, A = {spec.amplitude_m * 1e3:g} mm, f = {spec.frequency_hz:g} Hz, "
        f"m = {mass:g} kg, params '{args.params}'"
    )


def _print_summary(s: dict[str, Any]) -> None:
    sig = s["signal"]
    print(
        f"Simulated {s['duration_s']:.2f} s ({s['samples']} samples) of {sig['shape']} "
        f"A = {sig['amplitude_mm']:g} mm, f = {sig['frequency_hz']:g} Hz, m = {s['mass_kg']:g} kg"
        f" in {s['wall_s'] * 1e3:.0f} ms"
    )
    print(
        f"  weight u: {s['u_min_mm']:.2f} … {s['u_max_mm']:.2f} mm; force max "
        f"{s['force_max_n']:.1f} N (rest {s['preload_tension_n']:.1f} N)"
    )
    print(
        f"  fibre slack {s['slack_fraction'] * 100:.1f} % of the time "
        f"in {s['slack_episodes']} episode(s)"
    )
    for key in ("output", "plot"):
        if key in s:
            print(f"  wrote {s[key]}")
