"""Time windows (recordings.window) and the commands on them: cat, trim, info's events."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from mcap.reader import make_reader

from labstand.cli import main
from recordings import CorruptRecordingError, RecordingMetadata, open_recording
from recordings.convert import write_streams
from recordings.window import WindowError, cut, read_window

from .conftest import command, drive, gauges

EVENTS = [
    (0, "start", "situation 11"),
    (1_000_000_000, "note", "weight swings"),
    (2_499_500_000, "estop", "limit switch, lower"),
]


@pytest.fixture
def rich_mcap(tmp_path: Path, meta: RecordingMetadata) -> Path:
    """5 s at 2 kHz with 10 lost samples, drive polls every 20 ms and three events."""
    out = tmp_path / "rich.mcap"
    g = np.concatenate([gauges(3000), gauges(7000, start=3010)])
    c = np.concatenate([command(3000), command(7000, start=3010)])
    write_streams(out, meta, g, c, drive(250), EVENTS)
    return out


WINDOWS = [(None, None), (1.0, 2.0), (0.0, 0.0005), (1.4995, 1.5050), (4.2, None), (None, 0.7)]


@pytest.mark.parametrize("suffix", [".mcap", ".h5", ".csv", ".parquet"])
def test_a_window_is_the_cut_of_the_whole_recording(rich_mcap: Path, tmp_path: Path, suffix):
    path = tmp_path / f"rich{suffix}"
    if suffix != ".mcap":
        assert main(["convert", str(rich_mcap), str(path)]) == 0
    else:
        path = rich_mcap
    whole = open_recording(path)
    for start, end in WINDOWS:
        window = read_window(path, start, end)
        lo = whole.gauges["t_ns"][0] if start is None else round(start * 1e9)
        hi = whole.gauges["t_ns"][-1] if end is None else round(end * 1e9)
        expected = cut(whole, int(lo), int(hi))
        for stream in ("gauges", "command", "drive"):
            got, want = getattr(window.recording, stream), getattr(expected, stream)
            np.testing.assert_array_equal(got, want, err_msg=f"{stream} {start}…{end}")
        assert window.recording.events_array.tolist() == expected.events_array.tolist()
        assert (window.first_s, window.last_s) == (0.0, 5.0045)
    assert len(read_window(path, 1.0, 2.0).recording.gauges) == 2001 - 10  # 10 lost


def test_an_mcap_window_reads_only_the_chunks_around_it(rich_mcap: Path):
    """A chunk in the middle is damaged: the whole file is refused, a window before it reads."""
    with rich_mcap.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    gauges_id = next(c.id for c in summary.channels.values() if c.topic == "/gauges")
    chunks = [c for c in summary.chunk_indexes if gauges_id in c.message_index_offsets]
    middle = sorted(chunks, key=lambda c: c.message_start_time)[len(chunks) // 2]
    data = bytearray(rich_mcap.read_bytes())
    at = middle.chunk_start_offset + middle.chunk_length // 2  # inside its compressed bytes
    data[at : at + 8] = bytes(b ^ 0xFF for b in data[at : at + 8])
    rich_mcap.write_bytes(bytes(data))
    with pytest.raises(CorruptRecordingError):
        open_recording(rich_mcap)
    window = read_window(rich_mcap, 0.0, 0.2)
    assert len(window.recording.gauges) == 401


def test_window_errors(rich_mcap: Path):
    with pytest.raises(
        WindowError, match=r"--start 6 s is outside; the recording spans 0 … 5.0045"
    ):
        read_window(rich_mcap, 6.0, None)
    with pytest.raises(WindowError, match=r"--end -1 s is outside"):
        read_window(rich_mcap, None, -1.0)
    with pytest.raises(WindowError, match=r"--start 2 s must be before --end 2 s"):
        read_window(rich_mcap, 2.0, 2.0)


def test_cat_prints_the_window_as_csv(rich_mcap: Path, capsys):
    assert main(["cat", str(rich_mcap), "--start", "1", "--end", "1.01"]) == 0
    frame = pd.read_csv(io.StringIO(capsys.readouterr().out))
    assert list(frame.columns) == ["t_s", "x_mm", "u_mm", "F_N", "x_cmd_mm", "seq", "flags"]
    whole = open_recording(rich_mcap).frame().loc[1.0:1.01]
    assert len(frame) == 21
    np.testing.assert_array_equal(frame["t_s"], whole.index)
    np.testing.assert_array_equal(frame["F_N"], whole["F_N"])  # repr floats: exact
    np.testing.assert_array_equal(frame["seq"], whole["seq"])
    assert main(["cat", str(rich_mcap), "--channels", "F,x_mm", "--end", "0.001"]) == 0
    assert capsys.readouterr().out.splitlines()[0] == "t_s,F_N,x_mm"
    assert main(["cat", str(rich_mcap), "--events", "--start", "0.5"]) == 0
    assert (
        capsys.readouterr().out
        == "1.000000\tnote\tweight swings\n2.499500\testop\tlimit switch, lower\n"
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--start", "9"], "--start 9 s is outside; the recording spans 0 … 5.0045 s"),
        (["--start", "2", "--end", "1"], "--start 2 s must be before --end 1 s"),
        (["--channels", "x,speed"], "--channels 'x,speed': unknown channel(s) speed; known: x,"),
    ],
)
def test_cat_bad_input_is_one_line_exit_2(rich_mcap: Path, capsys, args, message):
    assert main(["cat", str(rich_mcap), *args]) == 2
    captured = capsys.readouterr()
    assert message in captured.err and captured.err.count("\n") == 1 and captured.out == ""


@pytest.mark.parametrize("suffix", [".h5", ".csv", ".mcap"])
def test_trim_writes_the_window_with_its_events_and_a_note(
    rich_mcap: Path, tmp_path, suffix, capsys
):
    out = tmp_path / f"part{suffix}"
    assert main(["trim", str(rich_mcap), "-o", str(out), "--start", "0.5", "--end", "2.5"]) == 0
    assert "t = 0.5 … 2.5 s, 2 event(s) kept" in capsys.readouterr().out
    part, whole = open_recording(out), open_recording(rich_mcap)
    expected = cut(whole, 500_000_000, 2_500_000_000)
    for stream in ("gauges", "command", "drive"):
        np.testing.assert_array_equal(getattr(part, stream), getattr(expected, stream))
    assert part.gauges["t_ns"][0] == 500_000_000  # times are kept, not shifted
    assert [k for _, k, _ in part.events_array.tolist()] == ["note", "estop"]
    assert part.metadata.stand_config == whole.metadata.stand_config
    assert part.metadata.operator_note == (
        "test run; trimmed by labstand to t = 0.5 … 2.5 s of rich.mcap (which spans 0 … 5.0045 s)"
    )


def test_cat_of_a_recording_without_command(tmp_path: Path, capsys):
    src, rec = tmp_path / "run.csv", tmp_path / "run.mcap"
    src.write_text("t_s,x_mm,u_mm,F_N\n0,1,2,3\n0.0005,1.5,2,3\n0.001,2,2,3\n", encoding="utf-8")
    assert main(["import", str(src), "-o", str(rec)]) == 0
    capsys.readouterr()
    assert main(["cat", str(rec), "--start", "0.0005"]) == 0
    assert (
        capsys.readouterr().out
        == "t_s,x_mm,u_mm,F_N,seq,flags\n0.0005,1.5,2.0,3.0,1,0\n0.001,2.0,2.0,3.0,2,0\n"
    )
    assert main(["cat", str(rec), "--channels", "x_cmd"]) == 2
    assert capsys.readouterr().err == f"labstand: error: {rec}: has no command stream (x_cmd)\n"


def test_trim_refuses_bad_input(rich_mcap: Path, tmp_path: Path, capsys):
    out = tmp_path / "part.mcap"
    for args, message in [
        (["--start", "3", "--end", "2"], "--start 3 s must be before --end 2 s"),
        (["--start", "7"], "--start 7 s is outside"),  # (an --end past it is clamped)
        ([], "give --start T and/or --end T (s)"),
    ]:
        assert main(["trim", str(rich_mcap), "-o", str(out), *args]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1
    assert main(["trim", str(rich_mcap), "-o", str(rich_mcap), "--start", "1", "--force"]) == 2
    assert "would overwrite the source" in capsys.readouterr().err
    assert main(["trim", str(rich_mcap), "-o", str(tmp_path / "p.txt"), "--start", "1"]) == 2
    assert not out.exists() and not list(tmp_path.glob("*.part*"))


def test_info_lists_the_events_and_why_the_run_ended(rich_mcap: Path, capsys):
    assert main(["info", str(rich_mcap)]) == 0
    text = capsys.readouterr().out
    assert "  events (3):\n" in text
    assert "        2.499500 s  estop   limit switch, lower\n" in text
    assert text.endswith("  ended: estop at 2.499500 s: limit switch, lower\n")
    assert main(["info", str(rich_mcap), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["events"] == 3
    assert info["event_list"][2] == {"t_s": 2.4995, "kind": "estop", "text": "limit switch, lower"}


@pytest.mark.parametrize("command_name", ["cat", "trim", "convert", "import", "info"])
def test_help(command_name: str, capsys):
    with pytest.raises(SystemExit) as info:
        main([command_name, "--help"])
    assert info.value.code == 0
    assert "usage: labstand" in capsys.readouterr().out
