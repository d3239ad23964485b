"""CSV and LabVIEW TDMS imports: column mapping, units, NI scaling, truncated files."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
from nptdms import ChannelObject, TdmsWriter

from labstand.cli import main
from recordings import Backend, ImportMappingError, open_recording
from recordings.csvio import read_csv
from recordings.foreign import parse_mapping


def test_csv_from_simulate_imports_to_the_same_values(simulated_mcap: Path, tmp_path: Path):
    csv, out = tmp_path / "sim.csv", tmp_path / "imported.h5"
    assert main(["simulate", "--situation", "11", "-o", str(csv)]) == 0
    assert main(["import", str(csv), "-o", str(out)]) == 0
    imported, original = open_recording(out), open_recording(simulated_mcap)
    assert imported.metadata.backend is Backend.IMPORT
    assert imported.metadata.source == "sim.csv"
    assert imported.metadata.sample_rate_hz == pytest.approx(2000.0)
    np.testing.assert_array_equal(imported.gauges["seq"], original.gauges["seq"])
    np.testing.assert_array_equal(imported.gauges["t_ns"], original.gauges["t_ns"])
    for name in ("x_mm", "u_mm", "force_n"):  # CSV keeps 9 significant digits
        np.testing.assert_allclose(imported.gauges[name], original.gauges[name], rtol=1e-8)
    assert len(imported.command) == 0
    assert np.isnan(imported.frame()["x_cmd_mm"]).all()  # no command in a CSV: said, not made up


def _foreign_csv(path: Path, drop_row: int | None = None) -> None:
    t_ms = np.arange(10) * 0.5
    rows = [
        f"{t:g};{x:g};{u:g};{f:g}"
        for i, (t, x, u, f) in enumerate(
            zip(
                t_ms,
                np.arange(10) * 1.0,
                np.arange(10) * 1e-3,
                0.045 + np.arange(10) * 1e-3,
                strict=True,
            )
        )
        if i != drop_row
    ]
    path.write_text("Time[ms];Pos;Disp[m];Force[kN]\n" + "\n".join(rows) + "\n", encoding="utf-8")


def test_csv_column_mapping_and_units(tmp_path: Path, capsys):
    src, out = tmp_path / "export.csv", tmp_path / "out.mcap"
    _foreign_csv(src, drop_row=6)
    code = main(
        [
            "import",
            str(src),
            "--map",
            "time=Time[ms]",
            "--map",
            "x=Pos[mm]",
            "--map",
            "u=Disp[m]",
            "--map",
            "F=Force[kN]",
            "--note",
            "legacy",
            "-o",
            str(out),
        ]
    )
    assert code == 0, capsys.readouterr().err
    rec = open_recording(out)
    np.testing.assert_array_equal(rec.gauges["seq"], [0, 1, 2, 3, 4, 5, 7, 8, 9])
    assert rec.lost_samples == 1
    np.testing.assert_allclose(rec.frame()["u_mm"], np.delete(np.arange(10) * 1.0, 6))
    np.testing.assert_allclose(rec.frame()["F_N"], np.delete(45.0 + np.arange(10), 6))
    np.testing.assert_array_equal(rec.gauges["t_ns"], np.delete(np.arange(10) * 500_000, 6))
    assert rec.metadata.operator_note.startswith("legacy (imported from export.csv")


def test_csv_mapping_errors(tmp_path: Path):
    src = tmp_path / "export.csv"
    _foreign_csv(src)
    with pytest.raises(ImportMappingError) as info:
        read_csv(src)
    assert str(info.value) == (
        f"{src}: no column for x, u, F (columns: Time[ms], Pos, Disp[m], Force[kN]); "
        "map them with --map FIELD=COLUMN[UNIT]"
    )
    with pytest.raises(ImportMappingError) as info:
        parse_mapping(["speed=Pos"])
    assert (
        str(info.value) == "--map 'speed=Pos': unknown field 'speed'; known: time, x, u, F, x_cmd"
    )
    with pytest.raises(ImportMappingError) as info:
        parse_mapping(["F=Force[lb]"])
    assert str(info.value) == "--map 'F=Force[lb]': unit 'lb' is not one of N, kN, mN, daN, lbf"
    with pytest.raises(ImportMappingError) as info:
        read_csv(src, mapping=parse_mapping(["time=Time[ms]", "x=Position", "u=Disp", "F=Force"]))
    assert str(info.value).startswith(f"{src}: no column 'Position' for x; columns: Time[ms]")
    src.write_text("t_s,x_mm,u_mm,F_N\n0,1,2,3\n0.0005,1,oops,3\n", encoding="utf-8")
    with pytest.raises(ImportMappingError) as info:
        read_csv(src)
    assert str(info.value) == (
        f"{src}: line 3: '0.0005,1,oops,3': column 'u_mm': 'oops' is not a finite number"
    )


def test_cli_import_errors_are_one_line(tmp_path: Path, capsys):
    src = tmp_path / "export.csv"
    _foreign_csv(src)
    assert main(["import", str(src), "--map", "x", "-o", str(tmp_path / "o.h5")]) == 2
    err = capsys.readouterr().err
    assert err == "labstand: error: --map 'x': expected FIELD=COLUMN or FIELD=COLUMN[UNIT]\n"
    (tmp_path / "run.txt").write_text("1,2,3\n")  # (a missing one is "no such file" first)
    assert main(["import", str(tmp_path / "run.txt"), "-o", str(tmp_path / "o.h5")]) == 2
    assert "cannot import '.txt'; use .csv or .tdms" in capsys.readouterr().err


START = np.datetime64("2014-03-05T09:30:00.250000")
SCALED_F = {  # raw counts → kN by the NI linear scale the DAQ stored
    "unit_string": "kN",
    "NI_Number_Of_Scales": 1,
    "NI_Scale[0]_Scale_Type": "Linear",
    "NI_Scale[0]_Linear_Slope": 1e-5,
    "NI_Scale[0]_Linear_Y_Intercept": 0.04,
    "NI_Scaling_Status": "unscaled",
}


def _tdms(path: Path, segments: int = 4, n: int = 500) -> None:
    wf = {"wf_increment": 0.0005, "wf_start_time": START, "wf_start_offset": 0.0}
    with TdmsWriter(path) as writer:
        for k in range(segments):
            i = np.arange(k * n, (k + 1) * n)
            writer.write_segment(
                [
                    ChannelObject("Run", "Drive", i * 0.01, properties={**wf, "unit_string": "mm"}),
                    ChannelObject("Run", "Dial", i * 1e-5, properties={**wf, "unit_string": "m"}),
                    ChannelObject("Run", "Force", (i % 100).astype(np.int32), properties=SCALED_F),
                ]
            )


MAP = ["--map", "x=Run/Drive", "--map", "u=Dial", "--map", "F=Force"]


def test_tdms_import_maps_rate_start_units_and_ni_scaling(tmp_path: Path):
    src, out = tmp_path / "legacy.tdms", tmp_path / "legacy.mcap"
    _tdms(src)
    assert main(["import", str(src), *MAP, "-o", str(out)]) == 0
    rec = open_recording(out)
    i = np.arange(2000)
    assert rec.metadata.sample_rate_hz == 2000.0
    assert datetime.fromisoformat(rec.metadata.start_time_utc) == datetime(
        2014, 3, 5, 9, 30, 0, 250000, tzinfo=UTC
    )
    np.testing.assert_array_equal(rec.gauges["t_ns"], i * 500_000)
    np.testing.assert_allclose(rec.gauges["x_mm"], i * 0.01)
    np.testing.assert_allclose(rec.gauges["u_mm"], i * 1e-2)  # m → mm
    np.testing.assert_allclose(rec.gauges["force_n"], (0.04 + 1e-5 * (i % 100)) * 1e3)  # kN → N
    assert rec.repairs == []


def test_truncated_tdms_is_trimmed_and_says_so(tmp_path: Path, capsys):
    src, out = tmp_path / "cut.tdms", tmp_path / "cut.h5"
    _tdms(src)
    data = src.read_bytes()
    src.write_bytes(data[: len(data) - 3000])  # LabVIEW killed while writing the last segment
    assert main(["import", str(src), *MAP, "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "repaired: channels of unequal length (Run/Drive " in printed
    rec = open_recording(out)
    n = len(rec.gauges)
    assert 1500 <= n < 2000
    assert f"trimmed to the shortest, {n} samples" in printed
    np.testing.assert_allclose(rec.gauges["x_mm"], np.arange(n) * 0.01)
    assert rec.events()["kind"].tolist() == ["repair"]  # the repair travels with the data
