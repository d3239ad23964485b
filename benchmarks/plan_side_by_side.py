"""Check: does the planned test settle an ambiguous diagnosis better than a random one?

Campaigns of the other truth stand (``sim.checks.otherstand``: its own integrator and
effect forms, a true stand drawn off nominal, one effect at drawn parameters) recorded
on a starting set (``--recordings``, default the other stand's ``gentle`` three: small
strokes, the fibre never slack, a lab sparing its fibre, where six of the nine truths
barely show), at each weight in turn. The first diagnosis is *ambiguous* when its named
effect has a rival it cannot tell apart (``indistinguishable_from``) or its answer is
wrong (the truth not named first; for ``none`` an effect named; for an effect outside
the catalogue anything but ``unexplained``). Each ambiguous campaign gets one more
recording twice, side by side on the same true stand: the motion ``labstand plan``
chooses (``plan_motion_for``, both weights), and one drawn at random among the motions
the same search admitted (the same count: one each), each run as long as a plan runs
(``sim.motions.PLAN_S``). Each is diagnosed again with the starting recordings. Right:
the truth named first (or the right verdict); settled: right with no rival left beside it.

Campaigns run in a process pool (``--jobs``); each finished one is appended to
``--out`` as one JSON line at once, and a rerun with the same ``--out`` skips campaigns
already there (``--only``: just these campaign numbers). ``--summary FILE`` prints the
counts of a results file.

Run: ``.venv/bin/python benchmarks/plan_side_by_side.py --campaigns 18 --jobs 1 --out r.jsonl``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np

CATALOGUE = (
    "fibre_viscoelastic", "fibre_transverse_vibration", "fibre_pulley_jump",
    "pulley_inertia_friction", "stick_slip_friction", "side_load_friction",
    "dial_gauge_calibration", "channel_time_skew", "force_gauge_dynamics",
)  # fmt: skip
#: The search's budget per plan, s: the whole grid on a loaded core.
BUDGET_S = 120.0


#: What each ranked candidate's entry keeps of the diagnosis' ranking.
REFIT_KEYS = ("params", "p_value", "p_family", "heldout_excess", "at_bound")


def _answer(d: dict[str, Any]) -> dict[str, Any]:
    named = [e["effect"] for e in d["effects"]]
    rivals = d["effects"][0]["indistinguishable_from"] if named else []
    ranked = [r["effect"] for r in d["ranking"]]
    # Each candidate's own refit as the planner takes it (its rival's size) and the
    # evidence for it: what a look at why a plan failed starts from.
    refits = {r["effect"]: {key: r.get(key) for key in REFIT_KEYS} for r in d["ranking"]}
    return {"verdict": d["verdict"], "named": named, "rivals": rivals, "ranking": ranked,
            "refits": refits}  # fmt: skip


def right(truth: str, answer: dict[str, Any]) -> bool:
    """The truth named first; ``none``: nothing named; outside the catalogue: unexplained."""
    named = answer["named"]
    if truth == "none":
        return not named
    if truth not in CATALOGUE:
        return not named and answer["verdict"] == "unexplained"
    return bool(named) and named[0] == truth


def settled(truth: str, answer: dict[str, Any]) -> bool:
    """Right, and no rival the recordings cannot tell from it."""
    return right(truth, answer) and not answer["rivals"]


def _diagnosis(traces: Sequence[Any], nominal: Any) -> dict[str, Any]:
    from sim.identify import diagnose

    result: dict[str, Any] = diagnose(traces, nominal).to_dict()
    return result


def _recorded(
    camp: Any, spec: Any, mass: float, name: str, rng: np.random.Generator, limits: Any = None
) -> Any:
    """One more recording of the campaign's true stand (its effects, the other weight too).

    ``limits``: the drive's (default: the stand file's).
    """
    from drivers.signals import plan_motion
    from sim.checks.otherstand import simulate
    from sim.checks.otherstand.gauges import Realism
    from sim.config import default_config
    from sim.identify.traces import make_trace

    config = default_config()
    rate = config.sample_rate_hz
    t, x = plan_motion(spec, limits or config.drive).sample(rate)
    run = simulate(camp.stand.with_(mass_kg=mass), camp.effects, x, rate)
    x_rec, u_rec, f_rec = Realism().apply(x, run.u_m, run.force_n, rate, rng)
    return make_trace(name, t, x_rec, u_rec, f_rec, mass)


def _other_recording(added: str) -> Any | None:
    """The other stand's recording ``SET:NAME`` (``OTHER_SETS``), None if there is none."""
    from sim.checks.otherstand.campaign import OTHER_SETS

    set_name, _, name = added.partition(":")
    return next((r for r in OTHER_SETS.get(set_name, ()) if r.name == name), None)


def _added(camp: Any, added: str, mass: float, rng: np.random.Generator) -> Any:
    """One recording of another set (``SET:NAME``) on the campaign's stand."""
    rec = _other_recording(added)
    if rec is None:  # ``main`` refuses it before any campaign runs
        raise ValueError(f"not a recording of the other stand: {added!r}")
    return _recorded(camp, rec.signal, mass, added, rng, rec.limits)


def campaign(
    seed: int, k: int, truth: str, mass: float, recordings: str, added: str | None = None
) -> dict[str, Any]:
    """One campaign: first diagnosis, and if ambiguous the plan, a random draw, both judged.

    ``added`` (``SET:NAME``): instead of the plan, that recording of another set is added
    to each ambiguous campaign, at its own weight, and judged the same way.
    """
    from labstand.commands.plan import noise_of
    from labstand.errors import CommandError
    from labstand.fitted import fitted_from_dict
    from labstand.planning import plan_motion_for, setting_for
    from sim.checks.otherstand.campaign import OTHER_SETS, make_other_campaign
    from sim.config import default_config
    from sim.envelope import SlackRule
    from sim.identify.traces import make_trace
    from sim.planner import as_planned

    started = time.perf_counter()
    config = default_config()
    nominal = config.stand_params("final", mass)
    rng = np.random.default_rng([seed, k])
    camp = make_other_campaign(nominal, [] if truth == "none" else [truth], rng,
                               OTHER_SETS[recordings], config.sample_rate_hz)  # fmt: skip
    traces = [make_trace(n, t, x, u, f, mass) for n, t, x, u, f in camp.recordings]
    first = _diagnosis(traces, config.stand_params("final"))
    out: dict[str, Any] = {
        "seed": seed, "campaign": k, "truth": truth, "mass_kg": mass, "recordings": recordings,
        "params": camp.effects, "first": _answer(first),
    }  # fmt: skip
    out["ambiguous"] = bool(out["first"]["rivals"]) or not right(truth, out["first"])
    if out["ambiguous"] and added is not None:
        extra = _added(camp, added, mass, np.random.default_rng([seed, k, 2]))
        again = _answer(_diagnosis([*traces, extra], config.stand_params("final")))
        out["added"] = {**again, "motion": added, "right": right(truth, again),
                        "settled": settled(truth, again)}  # fmt: skip
    elif out["ambiguous"]:
        fitted = fitted_from_dict(first, Path("(first diagnosis)"))
        rule = SlackRule(2.0, 0.25)
        masses = sorted(config.weights_kg.values())
        try:
            answer = plan_motion_for(fitted, config, masses, noise_of(traces), rule, BUDGET_S)
            setting = setting_for(fitted, config, noise_of(traces), rule)
        except CommandError as err:  # no rivals to separate: counted as no plan
            out["plan"] = {"why": str(err)}
            out["seconds"] = time.perf_counter() - started
            return out
        plan = answer.plan
        out["plan"] = {"why": answer.line(), "expected_separation": plan.expected_separation,
                       "separates": {f"{a} / {b}": v for (a, b), v in plan.separations.items()},
                       "admissible": plan.admissible, "complete": plan.complete,
                       "rivals": {r.name: [str(e) for e in r.effects]
                                  for r in setting.rivals}}  # fmt: skip
        if plan.best is not None:
            drawn = plan.options[int(np.random.default_rng([seed, k, 1]).integers(plan.admissible))]
            drawn = as_planned(setting, drawn)  # run as long as a plan runs
            for label, choice in (("planned", plan.best), ("random", drawn)):
                extra = _recorded(camp, choice.spec, choice.mass_kg, label,
                                  np.random.default_rng([seed, k, 2]))  # fmt: skip
                again = _answer(_diagnosis([*traces, extra], config.stand_params("final")))
                judged = {"right": right(truth, again), "settled": settled(truth, again)}
                out[label] = {**again, "motion": choice.describe(), **judged}
    out["seconds"] = time.perf_counter() - started
    return out


def summary(lines: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Counts over the ambiguous campaigns: planned and random, right and settled."""
    ambiguous = [r for r in lines if r["ambiguous"]]
    counted = [r for r in ambiguous if "planned" in r]
    added = [r for r in ambiguous if "added" in r]
    if added:  # ``--added``: that recording instead of a plan
        return {
            "campaigns": len(lines),
            "ambiguous": len(ambiguous),
            **{
                f"added_{what}": sum(r["added"][what] for r in added)
                for what in ("right", "settled")
            },
        }
    return {
        "campaigns": len(lines),
        "ambiguous": len(ambiguous),
        "with_a_plan": len(counted),
        **{
            f"{label}_{what}": sum(r[label][what] for r in counted)
            for label in ("planned", "random")
            for what in ("right", "settled")
        },
        "by_truth": {
            t: f"{sum(r['planned']['right'] for r in counted if r['truth'] == t)}"
            f"/{sum(r['random']['right'] for r in counted if r['truth'] == t)}"
            f" of {sum(r['truth'] == t for r in counted)}"
            for t in dict.fromkeys(r["truth"] for r in counted)
        },
    }


def _read(path: Path) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaigns", type=int, default=18)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--truths", default=",".join(CATALOGUE),
                        help="comma-separated: catalogue effects, none, outside ones")  # fmt: skip
    parser.add_argument("--recordings", default="gentle", help="the other stand's starting set")
    parser.add_argument("--only", help="comma-separated campaign numbers (default: all)")
    parser.add_argument("--jobs", type=int, default=1, help="campaigns at once (processes)")
    parser.add_argument("--out", type=Path, default=Path("plan_side_by_side.jsonl"))
    parser.add_argument("--summary", type=Path, help="only print the counts of this file")
    parser.add_argument("--added", metavar="SET:NAME",
                        help="instead of a plan, add this recording of another set "
                        "(e.g. moderate:burst) to each ambiguous campaign")  # fmt: skip
    args = parser.parse_args()
    if args.added is not None and _other_recording(args.added) is None:
        from sim.checks.otherstand.campaign import OTHER_SETS

        known = ", ".join(f"{s}:{r.name}" for s, rs in OTHER_SETS.items() for r in rs)
        parser.error(f"--added {args.added!r}: not a recording of the other stand ({known})")
    if args.summary is not None:
        print(json.dumps(summary(_read(args.summary)), indent=2))
        return
    # Each process its share of the cores (numba reads this when a worker first imports it).
    os.environ["NUMBA_NUM_THREADS"] = str(max(1, (os.cpu_count() or 1) // max(args.jobs, 1)))
    from sim.config import default_config

    truths = args.truths.split(",")
    masses = sorted(default_config().weights_kg.values())
    done = {(r["seed"], r["campaign"]) for r in _read(args.out)}
    todo = [
        (args.seed, k, truths[k % len(truths)], masses[(k // len(truths)) % len(masses)],
         args.recordings, args.added)
        for k in range(args.campaigns) if (args.seed, k) not in done
    ]  # fmt: skip
    if args.only:
        todo = [job for job in todo if str(job[1]) in args.only.split(",")]
    with (
        ProcessPoolExecutor(args.jobs, mp_context=get_context("spawn")) as pool,
        args.out.open("a") as sink,
    ):
        futures = {pool.submit(campaign, *job): job for job in todo}
        for future in as_completed(futures):
            try:
                line = future.result()
            except Exception as err:  # a failed campaign is reported, the others go on
                print(f"campaign {futures[future][1]} failed: {err!r}", file=sys.stderr)
                continue
            sink.write(json.dumps(line) + "\n")
            sink.flush()
            mark = ("planned " + ("right" if line["planned"]["right"] else "wrong")
                    + ", random " + ("right" if line["random"]["right"] else "wrong")
                    if "planned" in line
                    else f"{args.added} " + ("right" if line["added"]["right"] else "wrong")
                    if "added" in line else "not ambiguous" if not line["ambiguous"]
                    else "no plan")  # fmt: skip
            print(f"campaign {line['campaign']} ({line['truth']}, {line['mass_kg']:g} kg, "
                  f"{line['seconds']:.0f} s): first {line['first']['named']} "
                  f"{line['first']['rivals']}: {mark}", flush=True)  # fmt: skip
    print(json.dumps(summary(_read(args.out)), indent=2))


if __name__ == "__main__":
    main()
