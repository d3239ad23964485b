"""Stand files that used to end in a traceback: nesting, huge integers, wrong table types."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.config import MAX_NESTING, ConfigError, load_config

TOO_DEEP = MAX_NESTING + 1

BAD = [
    (f"[drive]\nspeed_max_m_s = {'[' * 5000}{']' * 5000}\n", "line 2: arrays or tables nested"),
    (f"a = {'{ b = ' * TOO_DEEP}1{' }' * TOO_DEEP}\n", "line 1: arrays or tables nested"),
    ("a" + ".b" * 5000 + " = 1\n", "key a.b.b.b"),
    (f"[drive]\nspeed_max_m_s = {10**400}\n", "[drive] speed_max_m_s: must be a number in range"),
    (f"[weights_kg]\nheavy = -{10**400}\n", "[weights_kg] heavy: must be a number in range"),
    (f"[drive]\nspeed_max_m_s = {'9' * 5000}\n", "not valid TOML: Exceeds the limit (4300"),
    (f"weights_kg = {'9' * 4000}\n", "[weights_kg] must be a table, got an integer of 13288"),
    ("weights_kg = 5\n", "[weights_kg] must be a table, got 5"),
    ("weights_kg = [1, 2]\n", "[weights_kg] must be a table, got [1, 2]"),
    (f'[weight]\ndefault = "{"x" * 500}"\n', "names no weight in [weights_kg]"),
    ("[drive]\nspeed_max_m_s = [" + "1, " * 500 + "1]\n", "must be a number, got list [1, 1, 1,"),
]


@pytest.mark.parametrize(("content", "message"), BAD)
def test_a_bad_stand_file_is_one_short_line_naming_the_key(
    tmp_path: Path, content: str, message: str
) -> None:
    path = tmp_path / "stand.toml"
    path.write_text(content)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    text = str(info.value)
    assert text.startswith(f"{path}: ")
    assert message in text
    assert "\n" not in text and len(text) < 700


def test_brackets_in_strings_and_comments_are_not_nesting(tmp_path: Path) -> None:
    path = tmp_path / "stand.toml"
    deep = "[" * 40
    path.write_text(
        f"# {deep} a comment\n"
        "[devices]\n"
        'drive = "tcp://127.0.0.1:5020"\n'
        f'gauges = "/dev/{deep}\\"{deep}"  # {deep}\n'
        f"[params.mine]\nstiffness_n_m = 5e4\ndamping_n_s_m = 30.0\nfriction = '''\n{deep}'''\n"
    )
    with pytest.raises(ConfigError, match=r"\[params.mine\] friction: names no \[friction"):
        load_config(path)  # parsed: refused for its value, not for brackets
    path.write_text(path.read_text().replace(f"'''\n{deep}'''", '"none"'))
    assert load_config(path).devices is not None
