"""``labstand plan`` from a saved diagnosis, and ``labstand run --plan`` running its answer."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from labstand.errors import CommandError, ExitCode
from labstand.fitted import fitted_from_dict
from labstand.planning import rivals_of
from recordings import open_recording
from tests.run.conftest import Outcome

GAUGE = {"cutoff_hz": 221.65, "damping_ratio": 0.715}
SKEW = {"force_skew_s": 0.0011, "displacement_skew_s": 0.0}


def _diagnosis(**changes: Any) -> dict[str, Any]:
    """A diagnosis as `labstand diagnose --json` wrote it for a campaign with a 1.1 ms skew."""
    data: dict[str, Any] = {
        "effect": "force_gauge_dynamics",
        "verdict": "explained",
        "effects": [
            {
                "effect": "force_gauge_dynamics",
                "params": GAUGE,
                "indistinguishable_from": ["channel_time_skew"],
            }
        ],
        "ranking": [
            {"effect": "force_gauge_dynamics", "params": GAUGE},
            {"effect": "channel_time_skew", "params": SKEW},
            {"effect": "fibre_transverse_vibration", "params": {}},
        ],
        "baseline_fit": {"stiffness_scale": 1.0, "damping_scale": 1.0, "friction_scale": 1.0},
        "baseline_intervals": {},
    }
    data.update(changes)
    return data


def test_the_rivals_a_diagnosis_leaves() -> None:
    where = Path("d.json")
    rivals, pairs = rivals_of(fitted_from_dict(_diagnosis(), where))
    assert pairs == [("force_gauge_dynamics", "channel_time_skew")]
    assert {r.name: [str(e) for e in r.effects] for r in rivals} == {
        "force_gauge_dynamics": ["force_gauge_dynamics:cutoff_hz=221.65,damping_ratio=0.715"],
        "channel_time_skew": ["channel_time_skew:force_skew_s=0.0011,displacement_skew_s=0"],
    }
    # named, told apart from all: against the runner-up and the baseline
    alone = _diagnosis()
    alone["effects"][0]["indistinguishable_from"] = []
    _, pairs = rivals_of(fitted_from_dict(alone, where))
    assert pairs == [
        ("force_gauge_dynamics", "channel_time_skew"),
        ("force_gauge_dynamics", "none"),
    ]
    # nothing named: each of the best against the baseline (which one, if any, is there?)
    _, pairs = rivals_of(fitted_from_dict(_diagnosis(effects=[], effect="none"), where))
    assert pairs == [("force_gauge_dynamics", "none"), ("channel_time_skew", "none")]
    with pytest.raises(CommandError, match="no rival explanations to separate"):
        rivals_of(fitted_from_dict(_diagnosis(effects=[], ranking=[]), where))


def test_a_further_effect_s_rival_is_planned_in_its_place() -> None:
    # The skew named first and told apart; a side load on top of it that the recordings
    # cannot tell from a pulley's inertia: the question left is that pair, each with
    # the skew beside it.
    side = {"friction_coeff": 0.05}
    pulley = {"inertia_kg_m2": 1e-4, "bearing_torque_n_m": 0.01, "load_coeff": 0.0}
    diagnosis = _diagnosis(
        effect="channel_time_skew",
        effects=[
            {"effect": "channel_time_skew", "params": SKEW, "indistinguishable_from": []},
            {
                "effect": "side_load_friction",
                "params": side,
                "indistinguishable_from": ["pulley_inertia_friction"],
            },
        ],
        ranking=[
            {"effect": "channel_time_skew", "params": SKEW},
            {"effect": "pulley_inertia_friction", "params": pulley},
            {"effect": "side_load_friction", "params": side},
        ],
    )
    rivals, pairs = rivals_of(fitted_from_dict(diagnosis, Path("d.json")))
    assert pairs == [("side_load_friction", "pulley_inertia_friction")]
    effects = {r.name: [e.name for e in r.effects] for r in rivals}
    assert effects == {
        "side_load_friction": ["channel_time_skew", "side_load_friction"],
        "pulley_inertia_friction": ["channel_time_skew", "pulley_inertia_friction"],
    }


def test_plan_then_run_the_plan(labstand: Callable[..., Outcome], tmp_path: Path) -> None:
    diagnosis = tmp_path / "diagnosis.json"
    diagnosis.write_text(json.dumps(_diagnosis()))
    plan_file = tmp_path / "plan.json"
    args = ["--diagnosis", diagnosis, "--mass-kg", "8.131", "--budget-s", "30", "-o", plan_file]
    result = labstand("plan", *args)
    assert result.code == 0, result.err
    line = result.out.splitlines()[0]
    assert " separates force_gauge_dynamics from channel_time_skew by " in line
    assert "; predicted slack " in line and " weight travel " in line
    plan = json.loads(plan_file.read_text())
    assert plan["why"] == line and plan["searched"] >= plan["admissible"] > 0
    assert plan["separates"][0]["rivals"] == ["force_gauge_dynamics", "channel_time_skew"]
    assert plan["expected_separation"] == plan["separates"][0]["separation"] > 0
    # decisive is the separation against 1 noise unit, and the line says so either way
    # (a 1.1 ms skew and a 222 Hz gauge: 0.6 at the simulated gauges' 0.1 N, the
    # noise without recordings; several units at the demo's recorded 0.02 N)
    assert plan["decisive"] is (plan["expected_separation"] >= 1.0)
    assert ("only (below 1: hardly told apart)" in line) is not plan["decisive"]
    predicted = plan["predicted"]
    assert predicted["weight_travel_mm"] < 0.9 * 120 and predicted["peak_tension_n"] < 0.9 * 400
    assert predicted["longest_slack_s"] < 0.9 * 0.25
    assert all(m > 0 for m in predicted["margins"].values())
    assert plan["signal"]["mass_kg"] == 8.131

    # the plan again with --json: the same answer (the search is deterministic)
    again = json.loads(labstand("plan", *args[:-2], "--json").out)
    assert again["signal"] == plan["signal"]

    out = tmp_path / "next.mcap"
    run = labstand("run", "--backend", "sim", "--plan", plan_file, "-o", out)
    assert run.code == 0, run.err
    assert "worst of 9 runs of the diagnosis " in run.out  # predicted with the plan's model
    meta = open_recording(out).metadata
    assert meta.signal is not None
    recorded = {k: v for k, v in meta.signal.items() if k != "situation"}
    assert recorded == {k: v for k, v in plan["signal"].items() if k != "mass_kg"}


def test_a_plan_runs_as_it_is(labstand: Callable[..., Outcome], tmp_path: Path) -> None:
    plan = tmp_path / "plan.json"
    signal = {
        "shape": "trapezoidal", "amplitude_mm": 20.0, "frequency_hz": 1.0, "cycles": 2,
        "ramp_fraction": 0.25, "dwell_start_s": 0.5, "dwell_end_s": 1.0, "mass_kg": 8.131,
    }  # fmt: skip
    plan.write_text(json.dumps({"signal": signal}))
    simulated = labstand("simulate", "--plan", plan, "--json")
    assert simulated.code == 0, simulated.err
    summary = json.loads(simulated.out)
    assert summary["signal"] == {k: v for k, v in signal.items() if k != "mass_kg"}
    assert summary["mass_kg"] == 8.131
    assert "the nominal model" in summary["prediction"]["model"]  # a plan without a model
    result = labstand("run", "--plan", plan, "--cycles", "5", "-o", tmp_path / "x.mcap")
    assert result.code == ExitCode.USAGE
    assert "--plan runs the plan's motion as it is: no --cycles beside it" in result.err
    plan.write_text(json.dumps({"signal": None}))
    result = labstand("run", "--plan", plan, "-o", tmp_path / "x.mcap")
    assert result.code == ExitCode.USAGE and "not a plan: no signal" in result.err
    assert not (tmp_path / "x.mcap").exists()
    result = labstand("plan")
    assert result.code == ExitCode.USAGE and "give recordings, or --diagnosis" in result.err
