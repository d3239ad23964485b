"""The run's parts without hardware: safety rules, clock, faults, [devices], display, refusals."""

from __future__ import annotations

import io
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

from drivers.interfaces import SAMPLE_DTYPE, DriveState
from drivers.signals import Shape, SignalSpec, plan_motion
from drivers.unidrive_profile import ProfileState
from labstand.commands.run import config_with_mass
from labstand.errors import ExitCode
from labstand.session.devices import default_backend
from labstand.session.display import LiveDisplay, PlainDisplay, RunStatus, make_display
from labstand.session.record import RunClock
from labstand.session.safety import EStopError, SafetyLimits, SafetyMonitor
from sim.config import ConfigError, config_from_dict, default_config
from sim.hardware.faults import Fault, FaultKind, FaultPlan, parse_fault
from tests.run.conftest import SHORT, Outcome


def block(n: int, start: int = 0, force: float = 45.0, x: float = 0.0) -> np.ndarray:
    """n samples at 2 kHz from sample ``start`` (SAMPLE_DTYPE)."""
    b = np.zeros(n, SAMPLE_DTYPE)
    b["seq"] = np.arange(start, start + n)
    b["t_device_us"] = b["seq"] * 500
    b["t_host_ns"] = int(b["t_device_us"][-1]) * 1000 + 3_000_000  # arrived 3 ms later
    b["force_n"], b["x_mm"] = force, x
    return b


def state(**changes: object) -> DriveState:
    values: dict[str, object] = {
        "t_host_s": 1.0, "drive_clock_s": 1.0, "position_m": 0.0, "velocity_m_s": 0.0,
        "reference_m": 0.0, "profile_time_s": 0.0, "profile_state": ProfileState.RUNNING,
        "status_word": 0b11, "trip_code": 0,
    }  # fmt: skip
    values.update(changes)
    return DriveState(**values)  # type: ignore[arg-type]


# ---- safety rules ------------------------------------------------------------------------
def test_position_envelope_and_speed() -> None:
    monitor = SafetyMonitor(SafetyLimits(), amplitude_mm=25.0, drive_speed_max_m_s=1.0)
    assert monitor.x_range_mm == (-5.0, 30.0)
    monitor.check_block(block(40, x=29.9))
    with pytest.raises(
        EStopError, match=r"x = 30\.50 mm \(gauges\) outside the allowed -5 … 30 mm"
    ):
        monitor.check_block(block(40, x=30.5))
    with pytest.raises(EStopError, match=r"x = -6\.00 mm \(drive\)"):
        monitor.check_drive(state(position_m=-0.006), expect_active=True)
    with pytest.raises(EStopError, match=r"drive speed 1\.200 m/s above the allowed 1\.1 m/s"):
        monitor.check_drive(state(velocity_m_s=-1.2), expect_active=True)


def test_trip_and_output_off() -> None:
    monitor = SafetyMonitor(SafetyLimits(), 25.0, 1.0)
    with pytest.raises(EStopError, match=r"^the drive tripped: trip 30 \(watchdog\)$"):
        monitor.check_drive(state(trip_code=30, status_word=0), expect_active=True)
    with pytest.raises(EStopError, match="output went off"):
        monitor.check_drive(state(status_word=0b01), expect_active=True)
    monitor.check_drive(state(status_word=0b01), expect_active=False)


def test_slack_counts_across_blocks_and_only_while_running() -> None:
    monitor = SafetyMonitor(SafetyLimits(slack_max_s=0.25), 25.0, 1.0)
    slack = [block(200, start=400 + 200 * i, force=0.5) for i in range(3)]  # 0.3 s slack
    for b in slack:
        monitor.check_block(b)  # the drive does not run: no e-stop
    monitor.running = True
    monitor.check_block(block(10, start=1000))  # taut again: the episode ends
    monitor.check_block(slack[0])  # 0.1 s
    monitor.check_block(slack[1])  # 0.2 s
    with pytest.raises(EStopError, match=r"fibre slack \(F < 2 N\) for 0\.30 s"):
        monitor.check_block(slack[2])


def test_short_slack_episodes_inside_one_block_are_tolerated() -> None:
    monitor = SafetyMonitor(SafetyLimits(), 25.0, 1.0)
    monitor.running = True
    b = block(2000)
    b["force_n"][100:300] = 0.0  # 0.1 s slack episodes, as in the paper's quick runs
    b["force_n"][700:1000] = 0.0  # 0.15 s
    monitor.check_block(b)
    b["force_n"][1200:1800] = 0.0  # 0.3 s
    with pytest.raises(EStopError, match=r"for 0\.30 s"):
        monitor.check_block(b)


def test_gauge_silence_and_bad_limits() -> None:
    monitor = SafetyMonitor(SafetyLimits(gauge_timeout_s=0.2), 25.0, 1.0)
    monitor.check_silence(0.19)
    with pytest.raises(EStopError, match=r"silent for 0\.21 s \(limit 0\.2 s\)"):
        monitor.check_silence(0.21)
    with pytest.raises(ValueError, match="slack_max_s must be > 0"):
        SafetyLimits(slack_max_s=0.0)


# ---- the recording's clock ---------------------------------------------------------------
def test_run_clock_maps_device_and_host_time() -> None:
    clock = RunClock()
    b0 = block(40, start=1000)
    clock.observe(b0)
    b1 = block(40, start=1040)
    b1["t_host_ns"] += 10_000_000  # this one waited 10 ms longer in a USB buffer
    clock.observe(b1)
    assert clock.offset_ns == 3_000_000  # the least delayed block wins
    gauges = clock.gauges(b0)
    assert gauges["t_ns"][0] == 0 and np.all(np.diff(gauges["t_ns"]) == 500_000)
    # a host instant 3 ms after the device sampled seq 1020 is 10 ms into the run
    t_host_s = (1020 * 500_000 + 3_000_000) / 1e9
    assert clock.host_ns(t_host_s) == 10_000_000
    profile = plan_motion(
        SignalSpec(Shape.QUASI_SINUSOIDAL, 0.02, 1.0, 1, dwell_start_s=0.0), default_config().drive
    )
    assert np.all(clock.command(b0, profile)["x_cmd_mm"] == 0)  # not started yet
    clock.profile_start_us = 1000 * 500 - 250_000  # started 0.25 s before the block
    cmd = clock.command(b0, profile)
    assert cmd["x_cmd_mm"][0] == pytest.approx(10.0)  # half the stroke at a quarter period


# ---- the simulated stand's fault hook ----------------------------------------------------
def test_fault_specs_and_plan() -> None:
    assert parse_fault("trip@1.5") == Fault(FaultKind.TRIP, 1.5, 45.0)
    assert parse_fault("garbage@0:64") == Fault(FaultKind.GARBAGE, 0.0, 64.0)
    assert math.isinf(parse_fault("modbus-mute@2").value)
    for bad in ("smoke@1", "trip@x", "trip@-1", "trip@1:7", "garbage@1:0"):
        with pytest.raises(ValueError, match="--fault"):
            parse_fault(bad)
    plan = FaultPlan((parse_fault("garbage@0.5"), parse_fault("trip@0.2")))
    assert plan.due(10.0, profile_running=False) == []  # counted from the profile's start
    assert plan.due(10.0, profile_running=True) == []
    assert [f.kind for f in plan.due(10.3, True)] == [FaultKind.TRIP]
    assert [f.kind for f in plan.due(11.0, True)] == [FaultKind.GARBAGE]


# ---- configuration -----------------------------------------------------------------------
def test_devices_table_is_optional_and_validated() -> None:
    assert default_config().devices is None and default_backend(default_config()) == "sim"
    config = config_from_dict(
        {"devices": {"drive": "tcp://10.0.0.5:502", "gauges": "/dev/ttyUSB0"}}
    )
    assert config.devices is not None and config.devices.gauges_baudrate == 921_600
    assert default_backend(config) == "stand"
    assert config_from_dict(config.to_dict()).devices == config.devices  # stored in recordings
    for table, message in (
        ({"drive": "tcp://x"}, r"\[devices\] gauges: missing"),
        ({"drive": "modbus://x", "gauges": "/dev/x"}, r"\[devices\] drive: must be a tcp://"),
        ({"drive": "tcp://x", "gauges": "/dev/x", "gauges_baudrate": 1.5}, "gauges_baudrate"),
        ({"drive": "tcp://x", "gauges": "/dev/x", "baud": 9600}, "baud: unknown key"),
    ):
        with pytest.raises(ConfigError, match=message):
            config_from_dict({"devices": table}, "stand.toml")


def test_the_recorded_stand_carries_the_actual_mass() -> None:
    config = default_config()
    assert config_with_mass(config, 3.096)["weight"]["default"] == "light"
    raw = config_with_mass(config, 5.5)
    assert config_from_dict(raw).default_mass_kg == 5.5
    assert config_from_dict(raw).weights_kg["heavy"] == 8.131


# ---- display -----------------------------------------------------------------------------
STATUS = RunStatus("running", 2.5, 6.0, 12.34, 11.2, 56.7, 2000.0, 5000, 0, 1, "running")


def test_live_display_on_a_terminal() -> None:
    stream = io.StringIO()
    display = LiveDisplay(Console(file=stream, force_terminal=True, width=100))
    with display:
        display.update(STATUS)
        display.update(STATUS)  # throttled: not drawn again
    text = stream.getvalue()
    for part in ("running", "2.5/6.0 s", "x   12.34 mm", "F    56.7 N", "2000 Hz", "corrupt 1"):
        assert part in text


def test_plain_lines_when_not_a_terminal() -> None:
    stream = io.StringIO()
    display = make_display(stream, plain_interval_s=60.0)
    assert isinstance(display, PlainDisplay)
    display.update(STATUS)
    display.update(STATUS)
    display.update(STATUS, force=True)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 and "x   12.34 mm" in lines[0] and "lost 0  corrupt 1" in lines[0]


# ---- refusals before anything is touched -------------------------------------------------
def stand_file(tmp_path: Path) -> Path:
    path = tmp_path / "stand.toml"
    path.write_text('[devices]\ndrive = "tcp://127.0.0.1:9"\ngauges = "/dev/nonexistent"\n')
    return path


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (
            ["--amplitude-mm", "95"],
            ExitCode.REFUSED,
            "refused: amplitude 95 mm exceeds the drive limit",
        ),
        (["-o", "x.csv"], ExitCode.USAGE, "cannot record '.csv'; use one of .h5, .hdf5, .mcap"),
        (["--backend", "stand"], ExitCode.USAGE, "no [devices] table"),
        (["--effect", "no_such"], ExitCode.USAGE, "unknown effect 'no_such'"),
        (
            ["--effect", "channel_time_skew:no_such=1"],
            ExitCode.USAGE,
            "channel_time_skew: unknown parameter 'no_such'",
        ),
        (
            ["--effect", "dial_gauge_calibration:gain_error=0.9"],
            ExitCode.USAGE,
            "gain_error = 0.9 is outside its admissible range [-0.5, 0.5]",
        ),
        (["--slack-max-s", "0"], ExitCode.USAGE, "slack_max_s must be > 0"),
        (
            ["-o", "no/such/dir/x.mcap"],
            ExitCode.USAGE,
            "no/such/dir/x.mcap: cannot write: no such folder no/such/dir",
        ),
    ],
)
def test_refused_or_bad_before_anything_starts(
    labstand: Callable[..., Outcome], tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    out = tmp_path / "never.mcap"
    result = labstand("run", *SHORT, "-o", out, *args)
    assert result.code == code
    assert message in result.err and len(result.err.strip().splitlines()) == 1
    assert not out.exists() and "Traceback" not in result.err


def test_the_stand_without_a_terminal_needs_yes(
    labstand: Callable[..., Outcome], tmp_path: Path
) -> None:
    stand = stand_file(tmp_path)
    result = labstand(
        "run", *SHORT, "--backend", "stand", "--stand", stand, "-o", tmp_path / "a.mcap"
    )
    assert result.code == ExitCode.REFUSED
    assert "must be confirmed, and there is no terminal to ask on: give --yes" in result.err
    assert SHORT[:2] == ["--backend", "sim"]
    # without --backend, a stand file with [devices] means the stand
    result = labstand("run", *SHORT[2:], "--stand", stand, "-o", tmp_path / "a.mcap")
    assert result.code == ExitCode.REFUSED
    # with --yes it goes on and finds no drive there (nothing listens on port 9)
    result = labstand(
        "run", *SHORT, "--backend", "stand", "--stand", stand, "--yes", "-o", tmp_path / "a.mcap"
    )
    assert result.code == ExitCode.FAILURE and "cannot reach the drive" in result.err
