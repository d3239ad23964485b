"""``labstand model``: properties of the model itself (linearised modes, the effects)."""

from __future__ import annotations

import argparse
import json
from typing import Any

from labstand.commands.common import add_stand_options, load_stand


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``labstand model``."""
    parser = sub.add_parser(
        "model", description="Properties of the baseline model: its modes, its effects."
    )
    model_sub = parser.add_subparsers(dest="model_command", metavar="WHAT", required=True)
    modes = model_sub.add_parser(
        "modes",
        help="linearised natural frequencies about static rest",
        description="Linearised natural frequencies about static rest. Without --mass-kg, "
        "one line per weight of the stand file (the paper's 3.096 and 8.131 kg).",
    )
    add_stand_options(modes, params=True)
    modes.add_argument("--mass-kg", type=float, help="weight mass, kg (default: every weight)")
    modes.add_argument("--json", action="store_true", help="print JSON (key modes_hz)")
    modes.set_defaults(func=run_modes)
    effects = model_sub.add_parser(
        "effects",
        help="the unmodelled effects and their parameters",
        description="The effects `labstand simulate --effect NAME[:param=value,...]` can "
        "switch on (STAND.md §5): each parameter's unit, default, plausible range (low–high) "
        "and admissible range (min–max). Equations: docs/effects.md.",
    )
    effects.add_argument("--json", action="store_true", help="print JSON (key effects)")
    effects.set_defaults(func=run_effects)


def run_modes(args: argparse.Namespace) -> int:
    """Print the modes for one mass or for every configured weight."""
    from sim.modes import linear_modes

    config = load_stand(args)
    masses = [args.mass_kg] if args.mass_kg is not None else sorted(config.weights_kg.values())
    rows: list[dict[str, Any]] = []
    for mass in masses:
        for mode in linear_modes(config.stand_params(args.params, mass)):
            rows.append(
                {
                    "mass_kg": mass,
                    "mode": mode.name,
                    "frequency_hz": mode.frequency_hz,
                    "damping_ratio": mode.damping_ratio,
                    "damped_frequency_hz": mode.damped_frequency_hz,
                }
            )
    if args.json:
        out = {
            "params": args.params,
            "modes_hz": [r["frequency_hz"] for r in rows],
            "mass_kg": [r["mass_kg"] for r in rows],
            "modes": rows,
        }
        print(json.dumps(out, indent=2))
        return 0
    print(f"Linearised modes, parameter set '{args.params}' ({config.source}):")
    for r in rows:
        print(
            f"  m = {r['mass_kg']:.3f} kg  {r['mode']}: {r['frequency_hz']:.2f} Hz, "
            f"damping ratio {r['damping_ratio']:.3f}"
        )
    return 0


def run_effects(args: argparse.Namespace) -> int:
    """List every effect with its parameters."""
    from sim.effects import EFFECTS

    if args.json:
        print(json.dumps({"effects": [info.to_dict() for info in EFFECTS.values()]}, indent=2))
        return 0
    for info in EFFECTS.values():
        print(f"{info.name} ({info.kind}): {info.summary}")
        print(f"  shows: {info.shows}")
        for p in info.params:
            print(
                f"  {p.name:<22} default {p.default:<9g} plausible {p.low:g} … {p.high:g}, "
                f"admissible {p.minimum:g} … {p.maximum:g} [{p.unit}]"
            )
    return 0
