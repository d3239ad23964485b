"""CSV as spreadsheets and stand PCs write it: decimal comma, preamble, encodings, bad lines."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from labstand.cli import main
from recordings import ImportMappingError, open_recording
from recordings.csvio import CsvOptions, read_csv

T = np.arange(6) * 0.0005
X = np.array([0.0, 0.25, 0.5, 1.25, 2.5, 3.75])
U = X * 0.9
F = 45.0 + X


def _rows(sep: str, decimal: str) -> list[str]:
    def num(v: float) -> str:
        return f"{v:g}".replace(".", decimal)

    return [sep.join(num(v) for v in row) for row in zip(T, X, U, F, strict=True)]


def _check_values(out: Path) -> None:
    rec = open_recording(out)
    np.testing.assert_array_equal(rec.gauges["t_ns"], np.arange(6) * 500_000)
    np.testing.assert_allclose(rec.gauges["x_mm"], X)
    np.testing.assert_allclose(rec.gauges["u_mm"], U)
    np.testing.assert_allclose(rec.gauges["force_n"], F)


@pytest.mark.parametrize("sep", [";", "\t"])
def test_spreadsheet_export_with_comma_decimals_preamble_and_cp1252(tmp_path: Path, sep, capsys):
    src, out = tmp_path / "export.csv", tmp_path / "out.mcap"
    preamble = ["# Export from stand PC 3, Prüfstand Süd", "# Operator: Müller; 20 °C"]
    header = sep.join(["t_s", "x_mm", "u_mm", "F_N"])
    text = "\r\n".join([*preamble, header, *_rows(sep, ",")]) + "\r\n"
    src.write_bytes(text.encode("cp1252"))
    args = ["import", str(src), "--decimal", ",", "--encoding", "cp1252", "-o", str(out), "--force"]
    assert main(args) == 0, capsys.readouterr().err
    _check_values(out)
    note = open_recording(out).metadata.operator_note
    assert "Export from stand PC 3, Prüfstand Süd / # Operator: Müller; 20 °C" in note
    # read as UTF-8 (the default), the same bytes are refused, naming the line
    assert main(["import", str(src), "--decimal", ",", "-o", str(out), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"labstand: error: {src}: line 1: not utf-8 text (byte 0xfc; try ")
    assert err.count("\n") == 1


def test_units_in_the_header_and_skip_rows(tmp_path: Path, capsys):
    src, out = tmp_path / "export.csv", tmp_path / "out.h5"
    lines = ["Stand PC export", "Run 17", "", "t [ms];x [mm];u [m];F [kN]"]
    rows = [
        f"{t * 1e3:g};{x:g};{u * 1e-3:g};{f * 1e-3:g}".replace(".", ",")
        for t, x, u, f in zip(T, X, U, F, strict=True)
    ]
    src.write_text("\n".join([*lines, *rows]) + "\n", encoding="utf-8")
    assert (
        main(["import", str(src), "--decimal", ",", "--skip-rows", "2", "-o", str(out), "--force"])
        == 0
    )
    _check_values(out)
    assert "preamble: Stand PC export / Run 17" in open_recording(out).metadata.operator_note
    capsys.readouterr()
    # without --skip-rows the first line is taken as the header
    assert main(["import", str(src), "--decimal", ",", "-o", str(out), "--force"]) == 2
    assert capsys.readouterr().err.endswith(
        "line 4: 't [ms];x [mm];u [m];F [kN]': 4 fields where the header (line 1) has 1 "
        "(a preamble? skip it with --skip-rows N)\n"
    )


def test_comment_lines_inside_the_data_keep_line_numbers(tmp_path: Path):
    src = tmp_path / "run.csv"
    src.write_text(
        "# preamble\nt_s,x_mm,u_mm,F_N\n0,1,2,3\n# pause\n\n0.0005,1,2,3\n0.001,1,2,x\n",
        encoding="utf-8",
    )
    with pytest.raises(ImportMappingError) as info:
        read_csv(src)
    assert (
        str(info.value) == f"{src}: line 7: '0.001,1,2,x': column 'F_N': 'x' is not a finite number"
    )
    src.write_text("% note\nt_s,x_mm,u_mm,F_N\n0,1,2,3\n0.0005,1,2,3\n", encoding="utf-8")
    assert len(read_csv(src, options=CsvOptions(comment="%")).gauges) == 2


def test_malformed_lines_name_the_line_and_show_it_shortened(tmp_path: Path, capsys):
    src, out = tmp_path / "run.csv", tmp_path / "out.mcap"
    long_tail = ";".join(["9,5"] * 40)
    src.write_text(
        "# Export\nt_s;x_mm;u_mm;F_N\n0;1;2;3\n0,0005;1;2;3;" + long_tail + "\n",
        encoding="utf-8",
    )
    assert main(["import", str(src), "--decimal", ",", "-o", str(out), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"labstand: error: {src}: line 4: '0,0005;1;2;3;9,5;9,5;")
    assert err.endswith("…': 44 fields where the header (line 2) has 4\n")
    assert len(err) - len(str(src)) < 150 and not out.exists()
    # comma decimals read with the default '.': the error says what to try
    src.write_text("t_s;x_mm;u_mm;F_N\n0;1,5;2;3\n", encoding="utf-8")
    assert main(["import", str(src), "-o", str(out), "--force"]) == 2
    assert capsys.readouterr().err == (
        f"labstand: error: {src}: line 2: '0;1,5;2;3': column 'x_mm': '1,5' is not a finite "
        "number (comma decimals? use --decimal ,)\n"
    )
    # a short line: the missing field is named
    src.write_text("t_s,x_mm,u_mm,F_N\n0,1,2,3\n0.0005,1,2\n", encoding="utf-8")
    assert main(["import", str(src), "-o", str(out), "--force"]) == 2
    assert "line 3: '0.0005,1,2': column 'F_N': empty" in capsys.readouterr().err


def test_bad_options_are_refused(tmp_path: Path, capsys):
    src, out = tmp_path / "run.csv", tmp_path / "out.mcap"
    src.write_text("t_s,x_mm,u_mm,F_N\n0,1,2,3\n0.0005,1,2,3\n", encoding="utf-8")
    assert main(["import", str(src), "--decimal", ",", "-o", str(out), "--force"]) == 2
    assert "with --decimal , the separator must be ';' or tab" in capsys.readouterr().err
    assert main(["import", str(src), "--encoding", "klingon", "-o", str(out), "--force"]) == 2
    assert capsys.readouterr().err == "labstand: error: --encoding 'klingon': unknown encoding\n"
    assert main(["import", str(src), "--skip-rows", "-1", "-o", str(out), "--force"]) == 2
    assert "--skip-rows -1: must be 0 or more" in capsys.readouterr().err
    assert main(["import", str(src), "--skip-rows", "5", "-o", str(out), "--force"]) == 2
    assert "no header line" in capsys.readouterr().err
    assert not out.exists()
