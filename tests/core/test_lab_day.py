"""Defects a lab day met, each pinned on a real ``labstand run --backend sim`` recording:
the final note after the last sample (cat --events, play), cat's number text, trim past
the end, and the diagnosis' length check at exactly 1 s."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from labstand.campaigns import trace_of
from labstand.live.player import Player
from recordings import open_recording
from sim.identify import DiagnosisInputError
from tests.live.test_play import SimClock
from tests.run.conftest import SHORT, labstand_process


def labstand(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "labstand", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.fixture(scope="module")
def run_rec(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("run") / "run.mcap"
    effect = ["--effect", "fibre_viscoelastic:relaxation_time_s=0.02", "--mass-kg", "3.096"]
    done = labstand_process("run", *SHORT, *effect, "--note", "lab day", "-o", out)
    assert done.code == 0, done.err
    return out


@pytest.mark.parametrize("suffix", [".mcap", ".h5", ".csv", ".parquet"])
def test_cat_events_ends_with_the_final_note(run_rec: Path, tmp_path: Path, suffix: str) -> None:
    rec = open_recording(run_rec)
    last_t, last_kind, last_text = rec.events_array.tolist()[-1]
    assert last_kind == "note" and last_t > rec.gauges["t_ns"][-1]  # after the last sample
    path = run_rec if suffix == ".mcap" else tmp_path / f"run{suffix}"
    if suffix != ".mcap":
        assert labstand("convert", run_rec, path).returncode == 0
    done = labstand("cat", path, "--events")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == len(rec.events_array)
    assert lines[-1] == f"{last_t / 1e9:.6f}\tnote\t{last_text}"
    inside = labstand("cat", path, "--events", "--end", "2").stdout.splitlines()
    assert last_text not in "".join(inside)  # a window that ends: only its own events


class Seen:
    """What the player published (the live view's publisher, minus the wire)."""

    def __init__(self) -> None:
        self.events: list[tuple[int, str, str]] = []
        self.polls = 0

    def gauges(self, block: object) -> None: ...

    def command(self, block: object) -> None: ...

    def model(self, t_ns: object, block: object) -> None: ...

    def drive(self, row: object) -> None:
        self.polls += 1

    def event(self, t_ns: int, kind: str, text: str) -> None:
        self.events.append((t_ns, kind, text))


def test_play_plays_the_final_note(run_rec: Path) -> None:
    rec = open_recording(run_rec)
    clock = SimClock()
    seen = Seen()
    stats = Player(rec, seen, None, clock).play()
    assert seen.events == [(int(t), str(k), str(x)) for t, k, x in rec.events_array.tolist()]
    assert stats.events == len(rec.events_array) and stats.drive == len(rec.drive) == seen.polls
    t0 = int(rec.gauges["t_ns"][0])
    assert clock.t == pytest.approx(100.0 + (int(rec.events_array["t_ns"][-1]) - t0) / 1e9)


def test_cat_prints_numbers_without_a_binary_tail(run_rec: Path) -> None:
    done = labstand("cat", run_rec, "--end", "1", "--channels", "x,u,F")  # the measured ones
    assert done.returncode == 0, done.stderr
    tails = re.findall(r"\.\d*(?:0{7,}|9{7,})[1-9]\d*", done.stdout)  # 21.854200000000002
    assert not tails, tails[:3]
    header, *rows = done.stdout.splitlines()
    table = np.array([[float(v) for v in row.split(",")] for row in rows])
    g = open_recording(run_rec).gauges[: len(rows)]
    np.testing.assert_array_equal(np.rint(table[:, 0] * 1e9).astype(np.int64), g["t_ns"])
    for col, name in ((1, "x_mm"), (2, "u_mm"), (3, "force_n")):
        np.testing.assert_allclose(table[:, col], g[name], rtol=1e-11, atol=1e-12)
    assert header == "t_s,x_mm,u_mm,F_N"


def test_trim_past_the_end_is_clamped_with_a_note(run_rec: Path, tmp_path: Path) -> None:
    out = tmp_path / "tail.mcap"
    done = labstand("trim", run_rec, "--start", "2", "--end", "99", "-o", out)
    assert done.returncode == 0, done.stderr
    assert "note: --end 99 s is past the end; cut at the end" in done.stdout
    rec, whole = open_recording(out), open_recording(run_rec)
    assert rec.gauges["t_ns"][-1] == whole.gauges["t_ns"][-1]
    assert "--end 99 s was past its end" in rec.metadata.operator_note
    before = labstand("trim", run_rec, "--start", "99", "-o", tmp_path / "x.mcap")
    assert before.returncode == 2 and "--start 99 s is outside" in before.stderr


def test_diagnosis_takes_exactly_one_second(run_rec: Path, tmp_path: Path) -> None:
    one, short = tmp_path / "one.h5", tmp_path / "short.h5"
    assert labstand("trim", run_rec, "--start", "1", "--end", "2", "-o", one).returncode == 0
    assert labstand("trim", run_rec, "--start", "1", "--end", "1.9995", "-o", short).returncode == 0
    trace = trace_of("one.h5", open_recording(one).frame(), 8.131)
    assert trace.mass_kg == 8.131
    with pytest.raises(DiagnosisInputError) as info:
        trace_of("short.h5", open_recording(short).frame(), 8.131)
    assert str(info.value) == "short.h5: spans 0.9995 s, too short to fit (need ≥ 1 s)"


def test_info_shows_mass_situation_and_effects(run_rec: Path, tmp_path: Path) -> None:
    text = labstand("info", run_rec).stdout
    assert "\n  mass 3.096 kg\n" in text
    assert "simulated effect fibre_viscoelastic: branch_stiffness_n_m = 20000, " in text
    assert "relaxation_time_s = 0.02\n" in text
    s10 = tmp_path / "s10.h5"
    assert labstand("simulate", "--situation", "10", "-o", s10).returncode == 0
    assert "  signal situation 10: " in labstand("info", s10).stdout


def test_compare_warns_when_signal_or_mass_differ(run_rec: Path, tmp_path: Path) -> None:
    other = tmp_path / "s11.mcap"
    assert labstand("simulate", "--situation", "11", "-o", other).returncode == 0
    done = labstand("compare", run_rec, other)
    assert done.returncode == 0, done.stderr
    assert "  warning: the drive signals differ (amplitude_mm 20.0 vs 25.0" in done.stdout
    assert "  warning: the masses differ (3.096 kg vs 8.131 kg)" in done.stdout
    same = labstand("compare", run_rec, run_rec)
    assert "warning" not in same.stdout
