"""Stand files that used to end in a traceback: nesting, huge integers, wrong table types."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.config import MAX_NESTING, MAX_STAND_FILE_BYTES, ConfigError, load_config

TOO_DEEP = MAX_NESTING + 1

BAD = [
    (f"[drive]\nspeed_max_m_s = {'[' * 5000}{']' * 5000}\n", "line 2: arrays or tables nested"),
    (f"a = {'{ b = ' * TOO_DEEP}1{' }' * TOO_DEEP}\n", "line 1: arrays or tables nested"),
    ("a" + ".b" * 5000 + " = 1\n", "line 1: arrays or tables nested"),  # before tomllib
    ("x = 1\n[a" + ".b" * TOO_DEEP + "]\n", "line 2: arrays or tables nested"),
    ("[acquisition]\nsample_rate_hz = 1e12\n", "sample_rate_hz: must be ≤ 100000, got 1e+12"),
    ("[acquisition]\nsample_rate_hz = 1e308\n", "sample_rate_hz: must be ≤ 100000"),
    (f"[drive]\nspeed_max_m_s = {10**400}\n", "[drive] speed_max_m_s: must be a number in range"),
    (f"[weights_kg]\nheavy = -{10**400}\n", "[weights_kg] heavy: must be a number in range"),
    (f"[drive]\nspeed_max_m_s = {'9' * 5000}\n", "not valid TOML: Exceeds the limit (4300"),
    (f"weights_kg = {'9' * 4000}\n", "[weights_kg] must be a table, got an integer of 13288"),
    ("weights_kg = 5\n", "[weights_kg] must be a table, got 5"),
    ("weights_kg = [1, 2]\n", "[weights_kg] must be a table, got [1, 2]"),
    (f'[weight]\ndefault = "{"x" * 500}"\n', "names no weight in [weights_kg]"),
    ("[drive]\nspeed_max_m_s = [" + "1, " * 500 + "1]\n", "must be a number, got list [1, 1, 1,"),
]


def test_a_stand_file_larger_than_a_megabyte_is_refused_before_it_is_read(tmp_path: Path) -> None:
    path = tmp_path / "stand.toml"
    path.write_text("# padding\n" * (MAX_STAND_FILE_BYTES // 10 + 1))
    with pytest.raises(ConfigError, match="larger than a stand file can be"):
        load_config(path)


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


def test_dots_of_numbers_and_strings_are_not_nesting(tmp_path: Path) -> None:
    path = tmp_path / "stand.toml"
    dots = ".".join("abcdefghijklmnopqrstu")
    path.write_text(
        f"drive.speed_max_m_s = 0.75  # {dots}\n"
        f'[devices]\ndrive = "tcp://{dots}:502"\ngauges = "/dev/ttyUSB0"\n'
    )
    config = load_config(path)
    assert config.drive.speed_max_m_s == 0.75
    assert config.devices is not None and config.devices.drive == f"tcp://{dots}:502"


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
