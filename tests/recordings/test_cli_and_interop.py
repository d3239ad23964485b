"""The info/convert/recover commands, and MCAP files encoded by the protobuf runtime."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mcap.writer import Writer

from labstand.cli import main
from recordings import open_recording
from recordings.mcap_writer import METADATA_NAME, TOPICS
from recordings.proto import file_descriptor_set, message_class

from .conftest import drive, gauges


def test_info_json_keys(simulated_mcap: Path, capsys):
    assert main(["info", str(simulated_mcap), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["duration_s"] == 4.0
    assert info["lost_samples"] == 0
    assert info["channels"]["gauges.force_n"] == {"unit": "N", "rate_hz": 2000.0, "samples": 8001}
    assert info["channels"]["command.x_cmd_mm"]["samples"] == 8001
    assert info["channels"]["drive.position_mm"] == {"unit": "mm", "rate_hz": None, "samples": 0}
    assert info["metadata"]["backend"] == "simulate"
    assert info["metadata"]["signal"]["shape"] == "trapezoidal"
    assert main(["info", str(simulated_mcap)]) == 0
    text = capsys.readouterr().out
    assert "4.000 s" in text and "0 lost in 0 gap(s)" in text


def test_recover_an_intact_file_and_refuse_overwriting(simulated_mcap: Path, tmp_path, capsys):
    fixed = tmp_path / "fixed.h5"
    assert main(["recover", str(simulated_mcap), "-o", str(fixed)]) == 0
    assert "nothing to repair: the file was intact" in capsys.readouterr().out
    np.testing.assert_array_equal(
        open_recording(fixed).gauges, open_recording(simulated_mcap).gauges
    )
    assert main(["convert", str(simulated_mcap), str(simulated_mcap)]) == 2
    assert "exists; nothing written (give --force" in capsys.readouterr().err
    assert main(["convert", str(simulated_mcap), str(simulated_mcap), "--force"]) == 2
    assert "would overwrite the source" in capsys.readouterr().err
    assert main(["convert", str(simulated_mcap), str(tmp_path / "x.xlsx")]) == 2
    assert "cannot write '.xlsx'" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.part*"))  # nothing half-written left behind


def test_mcap_encoded_by_the_protobuf_runtime_is_read(tmp_path: Path, meta):
    """Another writer's valid encodings (packed by the runtime, defaults omitted) decode."""
    path = tmp_path / "other.mcap"
    g, d = gauges(300), drive(5)
    with path.open("wb") as f:
        w = Writer(f)
        w.start()
        w.add_metadata(METADATA_NAME, {"json": meta.to_json()})
        fds = file_descriptor_set()
        ids = {
            topic: w.register_channel(topic, "protobuf", w.register_schema(name, "protobuf", fds))
            for topic, name in TOPICS.items()
            if topic != "/gauges/plot"
        }
        batch = message_class(TOPICS["/gauges"])
        for part in (g[:120], g[120:]):
            msg = batch(**{name: part[name].tolist() for name in g.dtype.names})
            w.add_message(ids["/gauges"], 1, msg.SerializeToString(), 1)
        state = message_class(TOPICS["/drive"])
        for row in d:  # enabled=False and trip_code=0 are left out by the runtime
            fields = {name: row[name].item() for name in d.dtype.names}
            w.add_message(ids["/drive"], 1, state(**fields).SerializeToString(), 1)
        w.finish()
    rec = open_recording(path)
    np.testing.assert_array_equal(rec.gauges, g)
    np.testing.assert_array_equal(rec.drive, d)
    assert len(rec.command) == 0 and len(rec.events_array) == 0


@pytest.mark.parametrize("suffix", [".mcap", ".h5"])
def test_empty_recording_is_refused(tmp_path: Path, meta, suffix: str):
    from recordings import InvalidDataError, open_writer

    path = tmp_path / f"empty{suffix}"
    with open_writer(path, meta) as w:
        w.write_event(0, "start", "")
    with pytest.raises(InvalidDataError) as info:
        open_recording(path)
    assert str(info.value) == f"{path}: the gauges stream holds no samples"
