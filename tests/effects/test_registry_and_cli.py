"""The effect registry, ``--effect`` parsing, and the CLI that exposes both."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from labstand.cli import main
from sim.effects import EFFECTS, EffectError, EffectSpec, parse_effect, parse_effects

#: STAND.md §5, verbatim and in order.
STAND_MD_NAMES = [
    "fibre_viscoelastic",
    "fibre_transverse_vibration",
    "fibre_pulley_jump",
    "pulley_inertia_friction",
    "stick_slip_friction",
    "side_load_friction",
    "dial_gauge_calibration",
    "channel_time_skew",
    "force_gauge_dynamics",
]
UNIT_SUFFIX = {"N/m": "_n_m", "s": "_s", "m": "_m", "kg·m²": "_kg_m2", "N·m": "_n_m",
               "m/s": "_m_s", "deg": "_deg", "Hz": "_hz"}  # fmt: skip


def test_the_nine_names_of_stand_md() -> None:
    assert list(EFFECTS) == STAND_MD_NAMES
    kinds = {n for n, i in EFFECTS.items() if i.kind == "measurement"}
    assert kinds == {"dial_gauge_calibration", "channel_time_skew", "force_gauge_dynamics"}


@pytest.mark.parametrize("name", STAND_MD_NAMES)
def test_every_parameter_is_documented_with_consistent_ranges(name: str) -> None:
    info = EFFECTS[name]
    assert info.summary and info.shows and info.params
    columns = [p.column for p in info.params] + [info.flag_column]
    assert len(set(columns)) == len(columns)
    for p in info.params:
        assert p.minimum <= p.low <= p.default <= p.high <= p.maximum, p.name
        assert p.description
        if p.unit != "1":  # SI unit in the name
            assert p.name.endswith(UNIT_SUFFIX[p.unit]), (p.name, p.unit)
    spec = EffectSpec(name)
    assert spec.resolved() == info.defaults()


def test_draws_are_reproducible_and_within_the_plausible_range() -> None:
    for info in EFFECTS.values():
        a = info.draw(np.random.default_rng(7))
        b = info.draw(np.random.default_rng(7))
        assert a == b
        for p in info.params:
            assert p.low <= a[p.name] <= p.high
        EffectSpec(info.name, a).resolved()


def test_parse_effect_reads_name_and_parameters() -> None:
    spec = parse_effect("fibre_viscoelastic:branch_stiffness_n_m=2e4, relaxation_time_s=0.01")
    assert spec == EffectSpec(
        "fibre_viscoelastic", {"branch_stiffness_n_m": 2e4, "relaxation_time_s": 0.01}
    )
    assert parse_effect("side_load_friction") == EffectSpec("side_load_friction")
    assert parse_effects(["none"]) == []
    assert str(spec) == "fibre_viscoelastic:branch_stiffness_n_m=20000,relaxation_time_s=0.01"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("fibre_vibration", "unknown effect 'fibre_vibration'; known: fibre_viscoelastic"),
        ("fibre_viscoelastic:tau=1", "unknown parameter 'tau'; expected one of"),
        ("fibre_viscoelastic:relaxation_time_s", "expected param=value"),
        ("fibre_viscoelastic:relaxation_time_s=fast", "must be a number (s), got 'fast'"),
        ("fibre_viscoelastic:relaxation_time_s=1e-5", "outside its admissible range"),
        ("channel_time_skew:force_skew_s=nan", "outside its admissible range"),
        ("fibre_pulley_jump:seats=2.5", "seats = 2.5 must be a whole number"),
        ("side_load_friction:friction_coeff=0.1,friction_coeff=0.2", "given twice"),
    ],
)
def test_bad_effect_specs_give_one_line_errors(text: str, message: str) -> None:
    with pytest.raises(EffectError) as err:
        parse_effect(text)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_model_effects_lists_every_parameter(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["model", "effects", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)["effects"]
    assert [e["name"] for e in listed] == STAND_MD_NAMES
    first = listed[0]["params"][0]
    assert {"name", "unit", "default", "low", "high", "minimum", "maximum"} <= set(first)
    assert main(["model", "effects"]) == 0
    text = capsys.readouterr().out
    assert "relaxation_time_s" in text and "plausible" in text


def _csv(path: Path) -> np.ndarray:
    return np.loadtxt(path, delimiter=",", skiprows=1)


def test_simulate_with_effects_and_seeded_noise(tmp_path: Path) -> None:
    args = ["simulate", "--situation", "10", "--effect", "dial_gauge_calibration:gain_error=0.03"]
    base, a, b, c = (tmp_path / f"{n}.csv" for n in ("base", "a", "b", "c"))
    assert main(["simulate", "--situation", "10", "-o", str(base)]) == 0
    assert main([*args, "--noise", "--seed", "4", "-o", str(a)]) == 0
    assert main([*args, "--noise", "--seed", "4", "-o", str(b)]) == 0
    assert main([*args, "--noise", "--seed", "5", "-o", str(c)]) == 0
    rb, ra, rb2, rc = _csv(base), _csv(a), _csv(b), _csv(c)
    assert np.array_equal(ra, rb2)  # same seed, same recording
    assert not np.array_equal(ra, rc)
    # u carries the 3 % gain (and µm noise), F only the noise; x is untouched.
    assert np.array_equal(ra[:, 1], rb[:, 1])
    gain = np.polyfit(rb[:, 2], ra[:, 2], 1)[0]
    assert gain == pytest.approx(1.03, abs=2e-3)
    assert np.std(ra[:, 3] - rb[:, 3]) == pytest.approx(0.1, rel=0.3)


def test_simulate_json_names_the_effects(capsys: pytest.CaptureFixture[str]) -> None:
    effects = ["--effect", "fibre_viscoelastic", "--effect", "channel_time_skew:force_skew_s=2e-3"]
    assert main(["simulate", "--situation", "11", *effects, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["effects"] == ["fibre_viscoelastic", "channel_time_skew:force_skew_s=0.002"]
    assert summary["noise_seed"] is None
    assert summary["slack_episodes"] >= 1  # counted on the true force


def test_simulate_refuses_bad_effects_with_usage_exit(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "--situation", "11", "--effect", "gremlins"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("labstand: error: unknown effect 'gremlins'") and err.count("\n") == 1
    twice = ["--effect", "fibre_viscoelastic", "--effect", "fibre_viscoelastic"]
    assert main(["simulate", "--situation", "11", *twice]) == 2
    assert "given twice" in capsys.readouterr().err
