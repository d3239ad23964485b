"""Full-rate plots from MCAP files: every batched sample carries its time in s (``t_s``).

Foxglove's Plot panel (x-axis "Message path") pairs ``/gauges.u_mm[:]`` with
``/gauges.t_s[:]`` sample by sample; the field is derived, written and never read back,
so files written before it (and readers before it) work unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from recordings import RecordingMetadata, open_recording, open_writer
from tests.recordings.conftest import command, drive, gauges
from tests.recordings.test_roundtrip import _classes_from_file_schema


def _write(path: Path, meta: RecordingMetadata, time_s: bool) -> None:
    with open_writer(path, meta, time_s=time_s) as w:
        for start in range(0, 5000, 100):
            w.write_gauges(gauges(100, start))
            w.write_command(command(100, start))
        w.write_drive_state(drive(10))


def test_every_batched_sample_has_its_time_in_seconds(
    tmp_path: Path, meta: RecordingMetadata
) -> None:
    path = tmp_path / "new.mcap"
    _write(path, meta, time_s=True)
    t_s: dict[str, list[float]] = {"/gauges": [], "/command": []}
    u: list[float] = []
    with path.open("rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if channel.topic in t_s:  # decoded with the schema stored in the file
                decoded = _classes_from_file_schema(schema).FromString(message.data)
                assert len(decoded.t_s) == len(decoded.t_ns)
                t_s[channel.topic].extend(decoded.t_s)
                if channel.topic == "/gauges":
                    u.extend(decoded.u_mm)
    expected = gauges(5000)
    np.testing.assert_array_equal(t_s["/gauges"], expected["t_ns"] / 1e9)
    np.testing.assert_array_equal(t_s["/command"], expected["t_ns"] / 1e9)
    np.testing.assert_array_equal(u, expected["u_mm"])


def test_files_with_and_without_t_s_read_the_same(tmp_path: Path, meta: RecordingMetadata) -> None:
    old, new = tmp_path / "old.mcap", tmp_path / "new.mcap"
    _write(old, meta, time_s=False)  # the layout before t_s
    _write(new, meta, time_s=True)
    a, b = open_recording(old), open_recording(new)
    for stream in ("gauges", "command", "drive"):
        np.testing.assert_array_equal(getattr(a, stream), getattr(b, stream))
    with old.open("rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if channel.topic == "/gauges":
                assert len(_classes_from_file_schema(schema).FromString(message.data).t_s) == 0
    # t_s costs 8 bytes a sample before compression; the regular times compress well
    assert new.stat().st_size < 1.25 * old.stat().st_size
