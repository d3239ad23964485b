"""Every signal, mass and e-stop value checked with its bounds before any device is opened.

``run`` gets a stand file whose devices answer nowhere (port 1 on loopback): a value
checked after the devices open would end in a connection failure (exit 1) instead of its
own one-line refusal. Bad values are exit 2; motions beyond the drive's limits exit 3.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from labstand.errors import ExitCode

from .conftest import labstand_process

BASE = ["--signal", "trapezoidal", "--amplitude-mm", "20", "--frequency-hz", "1", "--cycles", "2"]
NOWHERE = '[devices]\ndrive = "tcp://127.0.0.1:1"\ngauges = "/dev/null/none"\n'

CASES = [
    (["--amplitude-mm", "nan"], ExitCode.USAGE, "amplitude must be > 0 mm, got nan mm"),
    (["--amplitude-mm", "-20"], ExitCode.USAGE, "amplitude must be > 0 mm, got -20 mm"),
    (["--amplitude-mm", "95"], ExitCode.REFUSED, "amplitude 95 mm exceeds the drive limit"),
    (["--frequency-hz", "0"], ExitCode.USAGE, "frequency must be > 0 Hz"),
    (["--frequency-hz", "1e-9"], ExitCode.REFUSED, "frequency 1e-09 Hz is below the drive's"),
    (["--cycles", "0"], ExitCode.USAGE, "cycles must be ≥ 1"),
    (["--cycles", "1000000000"], ExitCode.REFUSED, "1000000000 cycles exceed"),
    (["--cycles", "30000"], ExitCode.REFUSED, "profile clock (Pr 20.34) wraps at 21475 s"),
    (["--dwell-end-s", "inf"], ExitCode.USAGE, "dwell_end_s must be a finite number"),
    (["--dwell-start-s", "nan"], ExitCode.USAGE, "dwell_start_s must be a finite number"),
    (["--dwell-end-s", "1e9"], ExitCode.REFUSED, "dwell_end_s 1e+09 s exceeds the drive's"),
    (["--ramp-fraction", "0.7"], ExitCode.USAGE, "ramp fraction must lie in (0, 0.5]"),
    (["--mass-kg", "-1"], ExitCode.USAGE, "mass must be > 0 kg, got -1"),
    (["--mass-kg", "0"], ExitCode.USAGE, "mass must be > 0 kg, got 0"),
    (["--mass-kg", "nan"], ExitCode.USAGE, "mass must be > 0 kg, got nan"),
]
SAFETY = [
    (["--gauge-timeout-s", "1e9"], "gauge_timeout_s must be ≤ 1, got 1e+09"),
    (["--position-margin-mm", "1e9"], "position_margin_mm must be ≤ 10, got 1e+09"),
    (["--slack-max-s", "60"], "slack_max_s must be ≤ 1, got 60"),
    (["--slack-force-n", "100"], "slack_force_n must be ≤ 15, got 100"),
    (["--gauge-timeout-s", "nan"], "gauge_timeout_s must be > 0, got nan"),
]


def _one_line(err: str, message: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], err
    assert "Traceback" not in err


@pytest.mark.parametrize(("extra", "code", "message"), CASES)
def test_simulate_checks_each_value(
    tmp_path: Path, extra: list[str], code: int, message: str
) -> None:
    out = tmp_path / "s.csv"
    got = labstand_process("simulate", *BASE, *extra, "-o", out, timeout_s=60)
    assert got.code == code
    _one_line(got.err, message)
    assert not out.exists()


@pytest.mark.parametrize(
    ("extra", "code", "message"),
    CASES + [(extra, ExitCode.USAGE, message) for extra, message in SAFETY],
)
def test_run_checks_each_value_before_any_device(
    tmp_path: Path, extra: list[str], code: int, message: str
) -> None:
    stand = tmp_path / "stand.toml"
    stand.write_text(NOWHERE)
    out = tmp_path / "x.mcap"
    got = labstand_process("run", "--stand", stand, "--yes", *BASE, *extra, "-o", out, timeout_s=60)
    assert got.code == code
    _one_line(got.err, message)
    assert not out.exists()


def test_the_nowhere_stand_fails_at_its_devices_when_every_value_is_good(tmp_path: Path) -> None:
    """The premise of the test above: good values reach the devices, which fail (exit 1)."""
    stand = tmp_path / "stand.toml"
    stand.write_text(NOWHERE)
    got = labstand_process(
        "run", "--stand", stand, "--yes", *BASE, "-o", tmp_path / "x.mcap", timeout_s=60
    )
    assert got.code == ExitCode.FAILURE, got.err
