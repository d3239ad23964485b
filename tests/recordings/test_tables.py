"""CSV and Parquet exports: units in the header/schema, and back to a recording losslessly."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from labstand.cli import main
from recordings import RecordingMetadata, open_recording
from recordings.convert import write_streams

from .conftest import command, drive, gauges

EVENTS = [
    (0, "start", "situation 11"),
    (1_000_000, "note", "Prüfer: Müller, 20 °C"),
    (
        2_499_500_000,
        "estop",
        'limit switch; "quoted", text',
    ),
]


@pytest.fixture
def rich_mcap(tmp_path: Path, meta: RecordingMetadata) -> Path:
    """A recording with every stream: lost samples, flags, drive polls, events."""
    out = tmp_path / "rich.mcap"
    g = np.concatenate([gauges(3000), gauges(2000, start=3010)])  # 10 samples lost
    g["seq"] += 65_530  # an unwrapped counter does not start at 0
    c = np.concatenate([command(3000), command(2000, start=3010)])
    write_streams(out, meta, g, c, drive(120), EVENTS)
    return out


def _same(a: Path, b: Path) -> None:
    ra, rb = open_recording(a), open_recording(b)
    for stream in ("gauges", "command", "drive"):
        np.testing.assert_array_equal(getattr(ra, stream), getattr(rb, stream), err_msg=stream)
    assert ra.events_array.tolist() == rb.events_array.tolist()
    assert ra.metadata == rb.metadata
    pd.testing.assert_frame_equal(ra.frame(), rb.frame(), check_like=False, check_flags=False)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_export_reads_back_losslessly(rich_mcap: Path, tmp_path: Path, suffix: str, capsys):
    table, back = tmp_path / f"rich{suffix}", tmp_path / "back.h5"
    assert main(["convert", str(rich_mcap), str(table)]) == 0
    assert main(["convert", str(table), str(back)]) == 0
    _same(rich_mcap, table)
    _same(rich_mcap, back)
    assert "Converted" in capsys.readouterr().out


def test_csv_export_has_units_in_the_header_and_reads_anywhere(rich_mcap: Path, tmp_path: Path):
    out = tmp_path / "rich.csv"
    assert main(["convert", str(rich_mcap), str(out)]) == 0
    lines = out.read_text(encoding="utf-8").splitlines()
    header = next(line for line in lines if not line.startswith("#"))
    assert header == "t_s,x_mm,u_mm,F_N,x_cmd_mm,seq,flags"
    events = [json.loads(x.split(": ", 1)[1]) for x in lines if x.startswith("# labstand-event")]
    assert events[1] == {"t_ns": 1_000_000, "kind": "note", "text": "Prüfer: Müller, 20 °C"}
    # any CSV reader that skips comment lines gets the table
    frame = pd.read_csv(out, comment="#")
    assert len(frame) == 5000 and frame["seq"].iloc[3000] == 65_530 + 3010
    np.testing.assert_array_equal(frame["x_mm"], open_recording(rich_mcap).gauges["x_mm"])
    # and labstand import takes it as a recording, keeping the metadata it carries
    rec = tmp_path / "imported.mcap"
    assert main(["import", str(out), "-o", str(rec)]) == 0
    _same(rich_mcap, rec)


def test_parquet_schema_carries_units_metadata_and_events(rich_mcap: Path, tmp_path: Path):
    out = tmp_path / "rich.parquet"
    assert main(["convert", str(rich_mcap), str(out)]) == 0
    table = pq.read_table(out)
    assert table.column_names == ["t_ns", "x_mm", "u_mm", "F_N", "x_cmd_mm", "seq", "flags"]
    units = {f.name: f.metadata[b"unit"].decode() for f in table.schema}
    assert units == {
        "t_ns": "ns",
        "x_mm": "mm",
        "u_mm": "mm",
        "F_N": "N",
        "x_cmd_mm": "mm",
        "seq": "",
        "flags": "",
    }
    extra = table.schema.metadata
    meta = json.loads(extra[b"labstand.metadata"])
    assert meta["operator_note"] == "test run" and meta["channels"]["gauges.x_mm"]["unit"] == "mm"
    assert [e["kind"] for e in json.loads(extra[b"labstand.events"])] == ["start", "note", "estop"]
    assert len(json.loads(extra[b"labstand.drive"])) == 120
    assert pd.read_parquet(out)["t_ns"].iloc[1] == 500_000


def test_imported_run_exports_without_a_command_column(tmp_path: Path):
    src, rec, out = tmp_path / "run.csv", tmp_path / "run.mcap", tmp_path / "out.parquet"
    src.write_text("t_s,x_mm,u_mm,F_N\n0,1,2,3\n0.0005,1.5,2,3\n0.001,2,2,3\n", encoding="utf-8")
    assert main(["import", str(src), "--mass-kg", "3.096", "-o", str(rec)]) == 0
    assert main(["convert", str(rec), str(out)]) == 0
    assert "x_cmd_mm" not in pq.read_table(out).column_names
    _same(rec, out)


def test_convert_refuses_what_it_cannot_write(rich_mcap: Path, tmp_path: Path, capsys):
    assert main(["convert", str(rich_mcap), str(tmp_path / "x.xlsx")]) == 2
    assert "cannot write '.xlsx'; use one of .csv, .h5, .hdf5, .mcap, .parquet" in (
        capsys.readouterr().err
    )
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(b"PAR1 not really")
    assert main(["convert", str(bad), str(tmp_path / "x.mcap")]) == 2
    assert "not a readable Parquet file" in capsys.readouterr().err


def test_a_command_on_its_own_clock_is_exported_interpolated_and_said(
    tmp_path: Path, meta: RecordingMetadata, capsys
):
    src, out = tmp_path / "own.mcap", tmp_path / "own.csv"
    c = command(1000)
    c["t_ns"] += 250_000  # halfway between gauge samples
    write_streams(src, meta, gauges(1000), c)
    assert main(["convert", str(src), str(out)]) == 0
    assert "the command has a clock of its own; written at the gauge times" in (
        capsys.readouterr().out
    )
    np.testing.assert_array_equal(
        open_recording(out).frame()["x_cmd_mm"].dropna(),
        open_recording(src).frame()["x_cmd_mm"].dropna(),
    )
