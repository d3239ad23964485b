"""Valid seed files of every reader and a seeded mutator over them.

Shared by the fuzz test (a few hundred cases in ``make test``) and
``benchmarks/fuzz_readers.py`` (thousands). Case ``i`` of seed ``s`` is the same file on
every machine: ``random.Random`` seeded with both picks the seed file (round robin over
the five kinds) and one to three edits: bit flips, bytes set to boundary integers,
truncation, duplication or deletion of a byte range, and edits that know the format
(an MCAP record's length or opcode, the fields after an HDF5 signature, a TDMS
lead-in, an HDF5 attribute or dataset replaced through h5py, a TOML or CSV value).
"""

from __future__ import annotations

import contextlib
import dataclasses
import random
import re
import struct
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import h5py
import numpy as np
from nptdms import ChannelObject, TdmsWriter

from recordings import RecordingError, make_metadata, open_recording, open_writer
from recordings.convert import summary
from recordings.csvio import write_csv
from recordings.foreign import parse_mapping
from recordings.tdmsio import read_tdms
from sim.config import ConfigError, default_config, load_config

KINDS = (".mcap", ".h5", ".csv", ".tdms", ".toml")
TDMS_MAP = parse_mapping(["x=Run/Drive", "u=Dial", "F=Force"])
Edit = Callable[[random.Random, bytearray], str]


# -- seeds ----------------------------------------------------------------------------------
def _streams(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from recordings import COMMAND_DTYPE, DRIVE_DTYPE, GAUGES_DTYPE

    i = np.arange(n)
    g = np.zeros(n, GAUGES_DTYPE)
    g["seq"], g["t_ns"] = i, i * 500_000
    g["x_mm"] = 25 * np.sin(i / 300)
    g["u_mm"], g["force_n"], g["flags"] = 0.9 * g["x_mm"], 45 + np.cos(i / 50), i % 3 == 0
    c = np.zeros(n, COMMAND_DTYPE)
    c["t_ns"], c["x_cmd_mm"] = g["t_ns"], g["x_mm"]
    m = n // 40
    d = np.zeros(m, DRIVE_DTYPE)
    d["t_ns"], d["position_mm"], d["speed_mm_s"] = np.arange(m) * 20_000_000, i[:m] * 0.1, 3.5
    d["status_word"], d["enabled"] = 0x41, True
    return g, c, d


def _recording(path: Path, n: int = 1200) -> None:
    start = datetime(2026, 11, 24, 12, 0, tzinfo=UTC)  # fixed, as is the host: same seeds anywhere
    meta = make_metadata(default_config().to_dict(), "sim", operator_note="fuzz seed", start=start)
    meta = dataclasses.replace(meta, host="fuzz", software_version="0")
    g, c, d = _streams(n)
    options = {"chunk_s": 0.1} if path.suffix == ".h5" else {"plot_rate_hz": 50.0}
    with open_writer(path, meta, flush_interval_s=0.2, **options) as w:
        w.write_event(0, "start", "situation 11")
        for k in range(0, n, 200):
            w.write_gauges(g[k : k + 200])
            w.write_command(c[k : k + 200])
            w.write_drive_state(d[k // 40 : (k + 200) // 40])
        w.write_event(int(g["t_ns"][-1]), "stop", "done: ünïcode")


def _tdms(path: Path, n: int = 300) -> None:
    start = np.datetime64(datetime(2014, 3, 5, 9, 30, tzinfo=UTC).replace(tzinfo=None), "us")
    wf = {"wf_increment": 0.0005, "wf_start_time": start, "wf_start_offset": 0.0}
    scaled = {
        **wf,
        "unit_string": "kN",
        "NI_Number_Of_Scales": 1,
        "NI_Scale[0]_Scale_Type": "Linear",
        "NI_Scale[0]_Linear_Slope": 1e-5,
        "NI_Scale[0]_Linear_Y_Intercept": 0.04,
        "NI_Scaling_Status": "unscaled",
    }
    with TdmsWriter(path) as writer:
        for k in range(2):
            i = np.arange(k * n, (k + 1) * n)
            writer.write_segment(
                [
                    ChannelObject("Run", "Drive", i * 0.01, properties={**wf, "unit_string": "mm"}),
                    ChannelObject("Run", "Dial", i * 1e-5, properties={**wf, "unit_string": "m"}),
                    ChannelObject("Run", "Force", (i % 100).astype(np.int32), properties=scaled),
                ]
            )


def _toml(path: Path) -> None:
    default = (Path(__file__).parents[2] / "sim" / "default_stand.toml").read_text()
    extra = (
        '\n[params.mine]\nstiffness_n_m = 5.0e4\ndamping_n_s_m = 30\nfriction = "mine"\n'
        "[friction.mine]\nspeed_m_s = [0.01, 0.1, 1.0]\nmu = [0.06, 0.05, 0.07]\n"
        'v_reg_m_s = 1e-3\n[devices]\ndrive = "tcp://127.0.0.1:5020"\n'
        'gauges = "/dev/ttyUSB0"\ngauges_baudrate = 921600\n'
    )
    path.write_text(default + extra, encoding="utf-8")


def write_seeds(directory: Path) -> dict[str, Path]:
    """One valid file per reader, written by the project's own writers (or npTDMS's)."""
    paths = {kind: directory / f"seed{kind}" for kind in KINDS}
    _recording(paths[".mcap"])
    _recording(paths[".h5"])
    g, c, _ = _streams(400)
    t_s = g["t_ns"] / 1e9
    write_csv(paths[".csv"], t_s, c["x_cmd_mm"], g["u_mm"], g["force_n"])
    _tdms(paths[".tdms"])
    _toml(paths[".toml"])
    return paths


# -- reading --------------------------------------------------------------------------------
def read(path: Path) -> None:
    """What the commands do with the file: read, check, summarise (``info``), frame.

    A recording is read as ``info`` reads it and as ``recover`` does (salvaging); the
    second read's outcome is the case's.
    """
    if path.suffix == ".toml":
        config = load_config(path)
        for name in config.parameter_sets:
            config.stand_params(name)
        return
    if path.suffix == ".tdms":
        recording = read_tdms(path, mapping=TDMS_MAP)
        recording.check()
    else:
        with contextlib.suppress(RecordingError):  # refused: `labstand recover` reads on
            open_recording(path)
        recording = open_recording(path, salvage=True)
    summary(recording)
    recording.frame()
    recording.events()


def expected_error(path: Path) -> type[Exception]:
    """The package's error type for the file's reader."""
    return ConfigError if path.suffix == ".toml" else RecordingError


# -- edits ----------------------------------------------------------------------------------
_BOUNDARY = (0, 1, 0x7F, 0x80, 0xFF, 0x7FFF, 0xFFFF, 2**31 - 1, 2**32 - 1, 2**63 - 1, 2**64 - 1)


def _boundary(rng: random.Random, width: int) -> bytes:
    value = rng.choice((*_BOUNDARY, rng.getrandbits(8 * width))) % 2 ** (8 * width)
    return value.to_bytes(width, "little")


def _set_int(rng: random.Random, data: bytearray, pos: int) -> str:
    width = rng.choice((1, 2, 4, 8))
    value = _boundary(rng, width)
    data[pos : pos + width] = value
    return f"set {width} bytes at {pos} to {value.hex()}"


def flip_bits(rng: random.Random, data: bytearray) -> str:
    spots = [rng.randrange(len(data) * 8) for _ in range(rng.choice((1, 1, 2, 4, 16)))]
    for bit in spots:
        data[bit // 8] ^= 1 << (bit % 8)
    return f"flip bits {spots[:4]}"


def set_int(rng: random.Random, data: bytearray) -> str:
    return _set_int(rng, data, rng.randrange(len(data)))


def truncate(rng: random.Random, data: bytearray) -> str:
    cut = rng.randrange(len(data))
    del data[cut:]
    return f"truncate at {cut}"


def duplicate(rng: random.Random, data: bytearray) -> str:
    start = rng.randrange(len(data))
    size = rng.randint(1, min(4096, len(data) - start))
    at = rng.randrange(len(data) + 1)
    data[at:at] = data[start : start + size]
    return f"copy {size} bytes from {start} to {at}"


def delete(rng: random.Random, data: bytearray) -> str:
    start = rng.randrange(len(data))
    size = rng.randint(1, min(4096, len(data) - start))
    del data[start : start + size]
    return f"delete {size} bytes at {start}"


def _near(rng: random.Random, data: bytearray, marks: tuple[bytes, ...], span: int) -> str:
    """Set an integer among the ``span`` bytes after one of the marks (a structure's fields)."""
    found = [m.start() for mark in marks for m in re.finditer(re.escape(mark), data)]
    if not found:
        return set_int(rng, data)
    pos = min(rng.choice(found) + rng.randrange(span), len(data) - 1)
    return _set_int(rng, data, pos)


def mcap_record(rng: random.Random, data: bytearray) -> str:
    """A top-level MCAP record: its length, its opcode, or the whole record removed/doubled."""
    records, pos = [], 8
    while pos + 9 <= len(data):
        _, length = struct.unpack_from("<BQ", data, pos)
        records.append((pos, 9 + length))
        pos += 9 + length
    if not records:
        return set_int(rng, data)
    start, size = rng.choice(records)
    what = rng.choice(("length", "opcode", "drop", "double", "field"))
    if what == "length":
        data[start + 1 : start + 9] = _boundary(rng, 8)
    elif what == "opcode":
        data[start] = rng.choice((0x00, 0x02, 0x05, 0x06, 0x0C, 0x0F, 0x80, 0xFF))
    elif what == "drop":
        del data[start : start + size]
    elif what == "double":
        data[start:start] = data[start : start + size]
    else:
        return _set_int(rng, data, start + 9 + rng.randrange(min(size - 9, 64) or 1))
    return f"MCAP record at {start}: {what}"


def hdf5_structure(rng: random.Random, data: bytearray) -> str:
    marks = (b"OHDR", b"OCHK", b"GCOL", b"BTHD", b"BTLF", b"TREE", b"FRHP", b"FHDB", b"FHIB")
    return "HDF5 " + _near(rng, data, marks, 48)


def tdms_structure(rng: random.Random, data: bytearray) -> str:
    marks = (b"TDSm", b"wf_increment", b"wf_start", b"NI_Scale", b"Force", b"unit_string")
    return "TDMS " + _near(rng, data, marks, 40)


_VALUES = (
    "0", "-1", "1e999", "-1e999", "nan", "inf", "9" * 400, '"x"', "[]", "[1]", "[[1], [2]]",
    "{}", "{a = 1}", "true", "1979-05-27T07:32:00Z", "[" * 40 + "]" * 40, '"\\u0000"', "1e-320",
)  # fmt: skip


def text_value(rng: random.Random, data: bytearray) -> str:
    """Replace a value (TOML ``key = value``, or a CSV field) or a line's text."""
    lines = bytes(data).decode("utf-8", errors="replace").split("\n")
    i = rng.randrange(len(lines))
    value = rng.choice(_VALUES)
    what = rng.choice(("value", "value", "drop", "double", "key"))
    if what == "value" and "=" in lines[i]:
        lines[i] = lines[i].split("=")[0] + "= " + value
    elif what == "value" and "," in lines[i]:
        fields = lines[i].split(",")
        fields[rng.randrange(len(fields))] = value
        lines[i] = ",".join(fields)
    elif what == "drop":
        del lines[i]
    elif what == "double":
        lines.insert(i, lines[i])
    else:
        lines.insert(i, f"{rng.choice(('a', 'weights_kg', 'drive', 'params'))} = {value}")
    data[:] = "\n".join(lines).encode()
    return f"text line {i}: {what} {value[:20]!r}"


_BYTES: tuple[Edit, ...] = (flip_bits, set_int, truncate, duplicate, delete)
EDITS: dict[str, tuple[Edit, ...]] = {
    ".mcap": (*_BYTES, mcap_record, mcap_record),
    ".h5": (*_BYTES, hdf5_structure, hdf5_structure),
    ".csv": (*_BYTES, text_value, text_value, text_value),
    ".tdms": (*_BYTES, tdms_structure, tdms_structure),
    ".toml": (flip_bits, truncate, duplicate, delete, *(text_value,) * 6),
}


def h5py_edit(rng: random.Random, path: Path) -> str:
    """An edit through h5py: an attribute of the wrong type or shape, a dataset replaced."""
    with h5py.File(path, "r+") as f:
        what = rng.choice(("attr", "attr", "dataset", "resize", "link"))
        if what == "attr":
            key = rng.choice(("schema_version", "metadata_json", "sample_rate_hz"))
            value = rng.choice(
                (np.void(b"\x00binary"), np.arange(3), b"\xff\xfe", "{", 2**62, 1.5, "[]")
            )
            del f.attrs[key]
            f.attrs[key] = value
            return f"h5py: attribute {key} = {value!r}"
        name = rng.choice(("gauges", "command", "drive", "events"))
        if what == "resize":
            size = rng.choice((0, 1, 10**6, 10**11))
            f[name].resize((size,))
            return f"h5py: resize /{name} to {size}"
        del f[name]
        if what == "link":
            f[name] = h5py.SoftLink(f"/{name}")
            return f"h5py: /{name} a soft link to itself"
        shape = rng.choice(((10,), (3, 4), ()))
        f.create_dataset(name, data=np.zeros(shape, rng.choice(("f8", "i4", "S4"))))
        return f"h5py: /{name} replaced by shape {shape}"


@dataclass(frozen=True)
class Case:
    """One mutated file and how it was made."""

    index: int
    path: Path
    edits: tuple[str, ...]

    def __str__(self) -> str:
        return f"case {self.index} ({self.path.suffix}: {'; '.join(self.edits)})"


def make_case(seeds: dict[str, bytes], seed: int, index: int, directory: Path) -> Case:
    """Write case ``index`` of ``seed`` into ``directory`` (the file name depends on neither)."""
    rng = random.Random(f"{seed}/{index}")
    kind = KINDS[index % len(KINDS)]
    path = directory / f"case{kind}"
    edits: list[str] = []
    data = bytearray(seeds[kind])
    if kind == ".h5" and rng.random() < 0.25:
        path.write_bytes(data)
        edits.append(h5py_edit(rng, path))
        data = bytearray(path.read_bytes())
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        if data:
            edits.append(rng.choice(EDITS[kind])(rng, data))
    path.write_bytes(data)
    return Case(index, path, tuple(edits))
