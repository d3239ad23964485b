"""Round trips (lossless), streaming writes, and independent readers of our files."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader

from drivers.signals import plan_motion
from labstand.cli import main
from recordings import Backend, open_recording, open_writer
from sim.config import config_from_dict, default_config
from sim.model import Model
from sim.situations import situation

from .conftest import command, drive, gauges


def _same(a, b) -> None:
    for name in ("gauges", "command", "drive"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.events_array.tolist() == b.events_array.tolist()
    assert a.metadata == b.metadata
    pd.testing.assert_frame_equal(a.frame(), b.frame(), check_exact=True)


def test_simulate_mcap_hdf5_mcap_dataframe_is_lossless(simulated_mcap: Path, tmp_path: Path):
    h5, back = tmp_path / "sim.h5", tmp_path / "back.mcap"
    assert main(["convert", str(simulated_mcap), str(h5)]) == 0
    assert main(["convert", str(h5), str(back)]) == 0
    first, middle, last = (open_recording(p) for p in (simulated_mcap, h5, back))
    _same(first, middle)
    _same(first, last)

    # and it is the model's output, as `labstand simulate` computed it
    config = default_config()
    preset = situation("11")
    _, x_m = plan_motion(preset.signal, config.drive).sample(2000.0)
    result = Model(config.stand_params("final", preset.mass_kg)).run(x_m, 2000.0)
    df = last.frame()
    n = len(x_m)
    assert df.index.name == "t_s" and len(df) == n
    np.testing.assert_array_equal(df["seq"], np.arange(n))
    np.testing.assert_array_equal(last.gauges["t_ns"], np.arange(n) * 500_000)
    np.testing.assert_array_equal(df["u_mm"], result.u_m * 1e3)
    np.testing.assert_array_equal(df["F_N"], result.force_n)
    np.testing.assert_array_equal(df["x_cmd_mm"], df["x_mm"])
    assert df.attrs["units"]["F_N"] == "N" and df.attrs["units"]["u_mm"] == "mm"
    meta = last.metadata
    assert meta.backend is Backend.SIMULATE
    assert meta.signal == {**preset.signal.to_dict(), "situation": "11"}  # as run stores it
    assert config_from_dict(meta.stand_config, "stored").stand_params("final") == (
        config.stand_params("final")
    )
    assert last.events()["kind"].tolist() == ["start", "stop"]


@pytest.mark.parametrize("suffix", [".mcap", ".h5"])
def test_streaming_writer_blocks_drive_and_events(tmp_path: Path, meta, suffix: str):
    path = tmp_path / f"run{suffix}"
    g, c, d = gauges(5003), command(5003), drive(120)
    with open_writer(path, meta) as w:
        w.write_event(0, "start", "go")
        at = 0
        for size in [1, 7, 100, 999, 1000, 1001, 1895]:  # odd sizes across batch/chunk edges
            block = g[at : at + size]
            as_dict = {name: block[name] for name in block.dtype.names}
            w.write_gauges(as_dict if size % 2 else block)
            w.write_command(c[at : at + size])
            at += size
        for row in d:
            w.write_drive_state({name: row[name] for name in d.dtype.names})
        w.write_event(int(g["t_ns"][-1]), "note", "ünïcødé ✓")
        w.write_event(int(g["t_ns"][-1]), "stop", "")
    rec = open_recording(path)
    np.testing.assert_array_equal(rec.gauges, g)
    np.testing.assert_array_equal(rec.command, c)
    np.testing.assert_array_equal(rec.drive, d)
    assert rec.events()["text"].tolist() == ["go", "ünïcødé ✓", ""]
    assert rec.repairs == []
    states = rec.drive_states()
    assert states["status_word"].iloc[0] == 0x41 and states["enabled"].dtype == bool


def test_a_live_reader_sees_mcap_data_up_to_the_last_flush(tmp_path: Path, meta):
    # (in one process HDF5 shares the open file, so this says nothing for .h5: test_kill does)
    path = tmp_path / "live.mcap"
    w = open_writer(path, meta)
    for start in range(0, 6000, 100):  # 3 s of data, writer left open
        w.write_gauges(gauges(100, start))
        w.write_command(command(100, start))
    seen = open_recording(path, salvage=True)
    assert seen.duration_s >= 2.4
    assert any("recovered" in line for line in seen.repairs)
    w.close()
    assert open_recording(path).duration_s == pytest.approx(2.9995)


def _classes_from_file_schema(schema) -> dict[str, type]:
    """Protobuf classes built from the schema bytes stored in the file (not our module)."""
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
    pool = descriptor_pool.DescriptorPool()
    for proto in fds.file:
        pool.Add(proto)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))


def test_mcap_reads_with_the_mcap_package_and_protobuf_runtime(simulated_mcap: Path):
    ours = open_recording(simulated_mcap)
    with simulated_mcap.open("rb") as f:
        for _ in StreamReader(f, validate_crcs=True).records:  # every CRC checked
            pass
    with simulated_mcap.open("rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None
        topics = {c.topic for c in summary.channels.values()}
        assert topics == {"/gauges", "/command", "/gauges/plot", "/drive", "/events"}
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
        values: dict[str, list[float]] = {"x_mm": [], "force_n": [], "seq": []}
        plot_seq: list[int] = []
        plot_force: list[float] = []
        for schema, channel, message in reader.iter_messages():
            assert schema.encoding == "protobuf" and channel.message_encoding == "protobuf"
            decoded = _classes_from_file_schema(schema).FromString(message.data)
            if channel.topic == "/gauges":
                for key, column in values.items():
                    column.extend(getattr(decoded, key))
                assert message.log_time == ours.metadata.start_time_ns + decoded.t_ns[0]
            elif channel.topic == "/gauges/plot":
                plot_seq.append(decoded.seq)
                plot_force.append(decoded.force_n)
        meta = {m.name: m.metadata for m in reader.iter_metadata()}
        attachments = {a.name: a.data for a in reader.iter_attachments()}
    np.testing.assert_array_equal(values["x_mm"], ours.gauges["x_mm"])
    np.testing.assert_array_equal(values["force_n"], ours.gauges["force_n"])
    np.testing.assert_array_equal(values["seq"], ours.gauges["seq"])
    np.testing.assert_array_equal(plot_seq, np.arange(0, len(ours.gauges), 20))  # 100 Hz
    np.testing.assert_array_equal(plot_force, ours.gauges["force_n"][::20])
    assert meta["labstand.recording"]["schema_version"] == "1"
    assert json.loads(attachments["stand.json"]) == default_config().to_dict()


def test_hdf5_reads_with_debian_h5dump(simulated_mcap: Path, tmp_path: Path):
    h5dump = shutil.which("h5dump")
    if h5dump is None:
        pytest.fail("h5dump is not installed (make system-tools installs hdf5-tools)")
    h5 = tmp_path / "sim.h5"
    assert main(["convert", str(simulated_mcap), str(h5)]) == 0
    out = subprocess.run(
        [h5dump, "-d", "/gauges", "-s", "3", "-c", "1", str(h5)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "H5T_COMPOUND" in out and '"force_n"' in out
    assert "(3): {\n" in out and "1500000" in out  # seq 3 at t_ns 3·500000
    attrs = subprocess.run(
        [h5dump, "-a", "/schema_version", str(h5)], capture_output=True, text=True, check=True
    ).stdout
    assert "(0): 1" in attrs


def test_hdf5_layout_attributes_and_plain_option(tmp_path: Path, meta):
    import h5py

    for compress, path in ((True, tmp_path / "gz.h5"), (False, tmp_path / "plain.h5")):
        with open_writer(path, meta, compress=compress) as w:
            for start in range(0, 2500, 250):
                w.write_gauges(gauges(250, start))
        with h5py.File(path, "r") as f:
            ds = f["gauges"]
            assert ds.chunks == (1000,) and ds.maxshape == (None,)
            assert ds.compression == ("gzip" if compress else None)
            assert ds.attrs["rate_hz"] == 2000.0 and ds.attrs["unit_force_n"] == "N"
            assert json.loads(ds.attrs["units"])["x_mm"] == "mm"
            assert f.attrs["schema_version"] == 1
            assert f.attrs["start_time_utc"] == meta.start_time_utc
            assert f.swmr_mode is False  # closed and reopened read-only
        np.testing.assert_array_equal(open_recording(path).gauges, gauges(2500))
