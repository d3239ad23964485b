"""Where everything sits is computed from the registry's order, and reading it loads no numba."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sim.config import StandConfig
from sim.effects import EFFECTS
from sim.physics import compose, kernel_source, layout
from sim.physics.runs import friction_arrays, parameter_row


def test_reading_the_effects_and_their_columns_loads_no_numba() -> None:
    code = (
        "import sys\n"
        "from sim.effects import EFFECTS, parse_effect\n"
        "spec = parse_effect('fibre_pulley_jump:onset_m=0.001')\n"
        "print(EFFECTS[spec.name].param('onset_m').column, 'numba' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    column, numba = out.stdout.split()
    assert int(column) == layout.R_PJ_ONSET
    assert numba == "False"


def test_the_row_follows_the_registry_order_effect_by_effect() -> None:
    expected = layout.STAND_COLUMNS
    for info in EFFECTS.values():
        if info.added:
            continue  # added with register: in the block from R_X
        assert info.flag_column == expected
        assert [p.column for p in info.params] == list(
            range(expected + 1, expected + 1 + len(info.params))
        )
        assert getattr(layout, f"R_{info.symbol}_ON") == info.flag_column
        for p in info.params:  # the kernel's name for each parameter is its column
            assert getattr(layout, f"R_{info.symbol}_{p.symbol}") == p.column
        expected += 1 + len(info.params)
    assert expected == layout.R_X_ON
    assert layout.N_ROW == layout.R_X + layout.N_X
    # The constants array continues where the row ends, nothing numbered twice.
    after = sorted(v for k, v in layout.constants(()).items() if k[:2] in ("D_", "S_", "E_"))
    assert after[0] == layout.N_ROW
    assert len(set(after)) == len(after)
    assert max(after) < layout.C_TABLE


def test_the_unions_state_names_follow_the_state_table() -> None:
    names = [name for name, _ in layout.STATES]
    assert [getattr(layout, f"Y_{name}") for name in names] == list(range(len(names)))
    assert len(names) == layout.NY
    assert set(layout.CARRIED) <= set(names)
    assert layout.constants(layout.TERMS)["NY"] == len(names)
    assert layout.constants(())["Y_Z"] == -1  # the baseline has no bristle


def test_the_heads_own_blocks_are_what_compose_writes_for_the_union() -> None:
    # The head shows the union's tuple helpers and hook calls (and imports the hooks, for
    # linting); a composed model runs the written ones.
    text = kernel_source.text()
    for name, written in (
        ("state", kernel_source.state_block(layout.TERMS)),
        ("hooks", kernel_source.hooks_block(layout.TERMS)),
    ):
        shown = ast.parse(kernel_source.block(text, name))
        shown.body = [node for node in shown.body if not isinstance(node, ast.ImportFrom)]
        assert ast.dump(shown) == ast.dump(ast.parse(written)), name


def test_an_effects_terms_are_in_its_own_folder_and_only_where_composed() -> None:
    files = dict(kernel_source.term_files(layout.TERMS))
    assert files["PJ"].parent.name == "fibre_pulley_jump"
    assert files["SL"].parent.name == "side_load_friction"
    baseline = compose.source_for(())
    assert "def pj_after_part" not in baseline and "def sl_friction" not in baseline
    union = compose.source_for(layout.TERMS)
    assert "def pj_after_part" in union and "pj_after_part(c, y, x, xd, h)" in union


def test_the_baseline_has_two_states_and_the_union_every_terms(stand: StandConfig) -> None:
    p = stand.stand_params("final", 8.131)
    c_args = (parameter_row(p), *friction_arrays(p.friction))
    base, union = compose.baseline(), compose.union()
    assert len(base.rest_state(base.pack(*c_args))) == 2
    assert len(union.rest_state(union.pack(*c_args))) == len(layout.STATES)
    assert layout.state_names(()) == ("U", "V")
    # Different sets, different files: a set's machine code is never another's.
    assert base.__name__ != union.__name__
    assert np.array_equal(base.pack(*c_args), union.pack(*c_args))


def test_the_hot_hooks_are_written_in_place_not_called() -> None:
    union = compose.source_for(layout.TERMS)
    for hook in kernel_source.SPLICED:
        site = union[union.index(f"# <splice {hook}>") : union.index(f"# </splice {hook}>")]
        assert f"_terms_{hook}(" not in site, hook
    segments = union[union.index("def _segments(") : union.index("def _tensions(")]
    assert "ext2 += c[S_LOFF]" in segments  # the pulley jump's extension, in place
    baseline = compose.source_for(())
    rhs = baseline[baseline.index("def _rhs(") : baseline.index("def _set_taut(")]
    assert "return _state(v, acc, 0.0, 0.0, 0.0" in rhs  # no term's rates


def test_a_spliced_hook_takes_the_sites_names_and_returns_once_at_its_end(
    tmp_path: Path,
) -> None:
    args = ("c", "v", "zone", "t2", "fric")
    path = tmp_path / "terms.py"
    path.write_text("def xx_friction(c, v, zone, t2, fric):\n    fric += 1.0\n    return fric\n")
    assert kernel_source._hook_body(path, "xx_friction", args, "fric") == [
        "fric += 1.0",
        "fric = fric",
    ]
    early = "    if v > 0:\n        return 0.0\n"
    path.write_text(f"def xx_friction(c, v, zone, t2, fric):\n{early}    return fric\n")
    with pytest.raises(ValueError, match="return once"):
        kernel_source._hook_body(path, "xx_friction", args, "fric")
    path.write_text("def xx_friction(c, speed, zone, t2, fric):\n    return fric\n")
    with pytest.raises(ValueError, match="must take"):
        kernel_source._hook_body(path, "xx_friction", args, "fric")
