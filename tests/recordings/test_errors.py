"""Each bad input is a RecordingError subclass with a one-line message naming the file."""

from __future__ import annotations

import dataclasses
import re
import struct
from pathlib import Path

import h5py
import numpy as np
import pytest

from labstand.cli import main
from recordings import (
    CorruptRecordingError,
    InvalidDataError,
    MissingChannelError,
    RecordingError,
    SchemaVersionError,
    TruncatedRecordingError,
    UnknownFormatError,
    WriterClosedError,
    mcap_writer,
    open_recording,
    open_writer,
)
from recordings.hdf5io import Hdf5RecordingWriter
from recordings.mcap_writer import McapRecordingWriter

from .conftest import command, gauges

SUFFIXES = [".mcap", ".h5"]


def _write(path: Path, meta, n: int = 4000, **options: float) -> None:
    with open_writer(path, meta, **options) as w:
        for start in range(0, n, 100):  # as a live run: a chunk per 0.5 s of data
            w.write_gauges(gauges(100, start))
            w.write_command(command(100, start))


def _raises(error: type[RecordingError], message: str, path: Path, **kw) -> None:
    with pytest.raises(error) as info:
        open_recording(path, **kw)
    assert str(info.value) == message
    assert "\n" not in str(info.value)


def _chunk_offsets(data: bytes) -> list[int]:
    pos, out = 8, []
    while pos + 9 <= len(data):
        opcode, length = struct.unpack_from("<BQ", data, pos)
        if opcode == 0x06:
            out.append(pos)
        if opcode == 0x0F:
            break
        pos += 9 + length
    return out


def test_truncated_mcap_is_refused_and_salvaged(tmp_path: Path, meta):
    path = tmp_path / "run.mcap"
    _write(path, meta, 4000, plot_rate_hz=0)  # 2 s: 4 chunks of 0.5 s, no plot chunks
    data = path.read_bytes()
    cut = _chunk_offsets(data)[3] + 100  # inside the 4th chunk
    path.write_bytes(data[:cut])
    # flushes after the blocks ending at 0.5495, 1.0495, 1.5495 s of data
    line = (
        f"the file is truncated (at byte {_chunk_offsets(data)[3]} of {cut} inside "
        "the data; its writer was killed?): 3 complete chunk(s), data up to t = 1.5495 s"
    )
    _raises(
        TruncatedRecordingError,
        f"{path}: {line}; run `labstand recover {path} -o FIXED.mcap`",
        path,
    )
    rec = open_recording(path, salvage=True)
    np.testing.assert_array_equal(rec.gauges, gauges(3100))
    assert rec.repairs == [f"recovered: {line}"]


def test_mcap_without_its_summary_is_truncated_but_complete(tmp_path: Path, meta):
    path = tmp_path / "run.mcap"
    _write(path, meta)
    path.write_bytes(path.read_bytes()[:-40])
    with pytest.raises(TruncatedRecordingError, match=r"truncated \(its summary;"):
        open_recording(path)
    np.testing.assert_array_equal(open_recording(path, salvage=True).gauges, gauges(4000))


def test_mcap_chunk_crc_mismatch(tmp_path: Path, meta):
    path = tmp_path / "run.mcap"
    _write(path, meta, plot_rate_hz=0)
    data = bytearray(path.read_bytes())
    crc_at = _chunk_offsets(bytes(data))[1] + 9 + 24  # 2nd chunk: uncompressed_crc field
    (crc,) = struct.unpack_from("<I", data, crc_at)
    struct.pack_into("<I", data, crc_at, crc ^ 1)
    path.write_bytes(bytes(data))
    with pytest.raises(CorruptRecordingError) as info:
        open_recording(path)
    assert re.fullmatch(
        rf"{re.escape(str(path))}: chunk 2: CRC 0x[0-9a-f]{{8}} does not match "
        rf"{crc ^ 1:#010x}",
        str(info.value),
    )
    salvaged = open_recording(path, salvage=True)  # the chunk is dropped, and said so
    assert salvaged.repairs[0].startswith("dropped chunk 2:")
    assert salvaged.lost_samples == 1000  # chunk 2: 0.5495 … 1.0495 s


def test_not_an_mcap_or_hdf5_file(tmp_path: Path):
    for name in ("junk.mcap", "junk.h5"):
        (tmp_path / name).write_bytes(b"this is not a recording\n" * 10)
    _raises(
        CorruptRecordingError,
        f"{tmp_path / 'junk.mcap'}: not an MCAP file (no MCAP magic at the start)",
        tmp_path / "junk.mcap",
    )
    with pytest.raises(CorruptRecordingError, match=r"junk\.h5: not a readable HDF5 file"):
        open_recording(tmp_path / "junk.h5")


def test_mcap_missing_channel(tmp_path: Path, meta, monkeypatch: pytest.MonkeyPatch):
    path = tmp_path / "run.mcap"
    monkeypatch.delitem(mcap_writer.TOPICS, "/drive")
    _write(path, meta)
    monkeypatch.undo()
    _raises(MissingChannelError, f"{path}: no channel '/drive' in the file", path)


def test_hdf5_missing_stream_and_field(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    _write(path, meta)
    with h5py.File(path, "a") as f:
        del f["drive"]
    _raises(MissingChannelError, f"{path}: no dataset /drive", path)
    _write(path, meta)
    with h5py.File(path, "a") as f:
        data = f["command"][...]
        del f["command"]
        f["command"] = data[["t_ns"]]
    _raises(MissingChannelError, f"{path}: /command has no field(s) x_cmd_mm", path)


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_non_monotonic_timestamps(tmp_path: Path, meta, suffix: str):
    path = tmp_path / f"run{suffix}"
    g = gauges(2000)
    g["t_ns"][5] = g["t_ns"][3]
    writer_cls = McapRecordingWriter if suffix == ".mcap" else Hdf5RecordingWriter
    with writer_cls(path, meta) as w:
        w._write_gauges(g)  # the hook, past the writer's own checks
    _raises(
        InvalidDataError,
        f"{path}: gauges.t_ns does not increase at sample 5 (2000000 then 1500000)",
        path,
    )


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_nan_samples(tmp_path: Path, meta, suffix: str):
    path = tmp_path / f"run{suffix}"
    g = gauges(2000)
    g["force_n"][3] = np.nan
    writer_cls = McapRecordingWriter if suffix == ".mcap" else Hdf5RecordingWriter
    with writer_cls(path, meta) as w:
        w._write_gauges(g)
    _raises(
        InvalidDataError, f"{path}: gauges.force_n is not finite at sample 3 (t = 0.001500 s)", path
    )


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_newer_schema_version(tmp_path: Path, meta, suffix: str):
    path = tmp_path / f"run{suffix}"
    _write(path, dataclasses.replace(meta, schema_version=2))
    _raises(
        SchemaVersionError,
        f"{path}: schema version 2 is newer than this labstand reads (1); update labstand",
        path,
    )


def test_unknown_suffix(tmp_path: Path, meta):
    with pytest.raises(UnknownFormatError) as info:
        open_writer(tmp_path / "run.txt", meta)
    assert (
        str(info.value)
        == f"{tmp_path / 'run.txt'}: cannot write '.txt'; use one of .h5, .hdf5, .mcap"
    )
    (tmp_path / "run.bin").write_bytes(b"\x00")  # a missing file is "no such file" first
    with pytest.raises(UnknownFormatError, match=r"cannot read '\.bin'; use one of \.csv, "):
        open_recording(tmp_path / "run.bin")


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_writer_refuses_bad_blocks_and_writes_after_close(tmp_path: Path, meta, suffix: str):
    path = tmp_path / f"run{suffix}"
    w = open_writer(path, meta)
    w.write_gauges(gauges(10))
    bad = gauges(10, 20)
    bad["u_mm"][4] = np.inf
    with pytest.raises(InvalidDataError, match=r"gauges\.u_mm is not finite at sample 4"):
        w.write_gauges(bad)
    with pytest.raises(InvalidDataError, match=r"gauges\.t_ns does not increase between blocks"):
        w.write_gauges(gauges(10, 5))
    with pytest.raises(InvalidDataError, match=r"gauges: block lacks field\(s\) flags"):
        w.write_gauges(
            {
                k: v
                for k, v in zip(("seq", "t_ns", "x_mm", "u_mm", "force_n"), [[1]] * 5, strict=True)
            }
        )
    w.close()
    with pytest.raises(WriterClosedError) as info:
        w.write_gauges(gauges(10, 10))
    assert str(info.value) == f"{path}: the recording is closed; cannot write"
    w.close()  # idempotent
    np.testing.assert_array_equal(open_recording(path).gauges, gauges(10))


def test_cli_reports_one_line_and_exit_code_2(tmp_path: Path, meta, capsys):
    path = tmp_path / "run.mcap"
    _write(path, meta)
    path.write_bytes(path.read_bytes()[:-2000])
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"labstand: error: {path}: the file is truncated")
    assert err.count("\n") == 1 and "Traceback" not in err
    assert main(["info", str(tmp_path / "missing.h5")]) == 2  # a missing input is bad input
    assert capsys.readouterr().err == f"labstand: error: no such file: {tmp_path / 'missing.h5'}\n"
