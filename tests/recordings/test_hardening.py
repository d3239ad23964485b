"""The guards the fuzzing needed, one by one, on files made by the real writers."""

from __future__ import annotations

import struct
from pathlib import Path

import h5py
import numpy as np
import pytest

from recordings import CorruptRecordingError, ImportMappingError, open_recording, open_writer
from recordings.csvio import read_csv

from .conftest import command, gauges


def _write(path: Path, meta, n: int = 2000) -> None:
    with open_writer(path, meta) as w:
        w.write_event(0, "start", "a note")
        for start in range(0, n, 100):
            w.write_gauges(gauges(100, start))
            w.write_command(command(100, start))


def _heap(data: bytes) -> int:
    pos = data.find(b"GCOL")
    assert pos >= 0, "the writer keeps its strings in a global heap"
    return pos


def test_a_global_heap_that_would_hang_the_library_is_refused(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    _write(path, meta)
    data = bytearray(path.read_bytes())
    start = _heap(data)
    # The first object's header: index 1, its size set to 0 would be a 16-byte step; an
    # index-0 (free space) header of size 0 is a step of 0 bytes: the library's endless loop.
    first = start + 16
    assert struct.unpack_from("<H", data, first)[0] == 1
    data[first : first + 16] = struct.pack("<HH4xQ", 0, 0, 0)
    path.write_bytes(data)
    with pytest.raises(CorruptRecordingError) as info:
        open_recording(path)
    assert str(info.value) == (
        f"{path}: global heap collection at byte {start} is damaged: object 0 at byte "
        f"{first} has size 0; the HDF5 library would never finish reading it"
    )


def test_the_words_gcol_in_a_note_do_not_trip_the_heap_check(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    with open_writer(path, meta) as w:
        w.write_event(0, "note", "GCOL\x01 is what a heap collection starts with")
        w.write_gauges(gauges(100))
        w.write_command(command(100))
    assert open_recording(path).events()["text"].iloc[0].startswith("GCOL")


def test_a_dataset_larger_than_the_file_is_refused_before_reading(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    _write(path, meta)
    with h5py.File(path, "a") as f:
        f["gauges"].resize((2**40,))  # metadata only: no chunk is written
    size = path.stat().st_size
    with pytest.raises(CorruptRecordingError) as info:
        open_recording(path)
    message = str(info.value)
    assert message.startswith(f"{path}: dataset /gauges has shape (1099511627776,), larger ")
    assert f"than the file ({size / 1000:.3g} kB) can hold" in message


def test_a_stream_that_is_a_link_is_not_followed(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    _write(path, meta)
    with h5py.File(path, "a") as f:
        del f["drive"]
        f["drive"] = h5py.SoftLink("/drive")  # a cycle
    with pytest.raises(CorruptRecordingError, match=r": /drive is a SoftLink, not a dataset$"):
        open_recording(path)


def test_a_field_of_the_wrong_type_and_an_attribute_of_the_wrong_shape(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    _write(path, meta)
    with h5py.File(path, "a") as f:
        rows = f["command"][...]
        del f["command"]
        text = np.array([str(v) for v in rows["x_cmd_mm"]], dtype=h5py.string_dtype())
        table = np.empty(len(rows), [("t_ns", "<i8"), ("x_cmd_mm", h5py.string_dtype())])
        table["t_ns"], table["x_cmd_mm"] = rows["t_ns"], text
        f["command"] = table
    with pytest.raises(CorruptRecordingError, match=r"/command field 'x_cmd_mm' has type object"):
        open_recording(path)
    with h5py.File(path, "a") as f:
        f.attrs["schema_version"] = np.array([1, 1])
    with pytest.raises(CorruptRecordingError, match=r"schema_version is an array of shape \(2,\)"):
        open_recording(path)


def test_an_mcap_chunk_claiming_gigabytes_is_refused_before_allocating(tmp_path: Path, meta):
    path = tmp_path / "run.mcap"
    _write(path, meta)
    data = bytearray(path.read_bytes())
    pos = 8
    while data[pos] != 0x06:  # the first chunk record
        pos += 9 + struct.unpack_from("<Q", data, pos + 1)[0]
    # Chunk: start time, end time (8 + 8), uncompressed size (8), CRC (4), ...
    struct.pack_into("<Q", data, pos + 9 + 16, 2**40)
    path.write_bytes(data)
    with pytest.raises(CorruptRecordingError, match=r"chunk 1: claims 1099511627776 bytes"):
        open_recording(path)


def test_a_csv_with_a_ragged_line_is_one_line(tmp_path: Path):
    path = tmp_path / "run.csv"
    path.write_text("t_s,x_mm,u_mm,F_N\n0,1,2,3\n0.1,1,2,3,4,5\n")
    with pytest.raises(ImportMappingError) as info:
        read_csv(path)
    assert "\n" not in str(info.value)
    assert str(info.value) == (
        f"{path}: line 3: '0.1,1,2,3,4,5': 6 fields where the header (line 1) has 4"
    )


def test_a_unit_conversion_that_overflows_names_the_sample(tmp_path: Path):
    path = tmp_path / "run.csv"
    path.write_text("t_s,x[m],u_mm,F_N\n0,1,2,3\n0.1,1e307,2,3\n0.2,1,2,3\n")
    with pytest.raises(ImportMappingError) as info:
        read_csv(path)
    assert str(info.value) == (
        f"{path}: column 'x[m]': value 1e+307 m at sample 1 is too large to convert to mm"
    )


def test_an_event_text_that_is_not_utf8_is_read_and_said_so(tmp_path: Path, meta):
    path = tmp_path / "run.h5"
    _write(path, meta)
    with h5py.File(path, "a") as f:
        events = f["events"]
        row = events[0]
        row["text"] = b"a not\xff"  # a flipped bit in the heap: no longer UTF-8
        events[0] = row
    recording = open_recording(path)
    assert recording.events()["text"].iloc[0] == "a not\ufffd"
    assert recording.repairs == [
        "/events.text row 0 is not UTF-8: decoded with replacement characters"
    ]
