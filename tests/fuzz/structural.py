"""Structural and semantic fuzz cases, beyond ``corpus.py``'s byte mutations (issue 31).

Case ``i`` of seed ``s`` is the same file on every machine. Strategies:

* MCAP: a cut at a top-level record (±1 byte, mid-record), two records swapped, a chunk
  duplicated, the footer's offsets set to boundary values, a chunk re-packed with a cut
  or edited inner record and a *correct* size and CRC; a file rewritten through the
  writer's hooks (past its checks) with NaN, times going back, huge gaps, int64
  extremes, long and control-character texts;
* HDF5: a cut at an object-header signature (±1), and checksum-valid h5py edits: a group
  or a 2-D/scalar dataset for a stream, soft/external links, big-endian or missing
  fields, crafted ``metadata_json`` (a signal without shape, a start before 1970, a
  rate of 1e12), times that jump to 2⁶²;
* CSV: preamble events of 1e400, a header of thousands of names (duplicated), BOM,
  UTF-16, NUL bytes, long lines, and an ``--encoding`` that is a bytes codec;
* Parquet: key-value metadata replaced (deep JSON, 2⁷⁰, null), columns of the wrong type;
* stand TOML: dotted keys and tables thousands deep, sample rates of 1e12/1e308/nan.

``read`` takes a case through every read path in-process: the whole read (``info``),
the salvaging read (``recover``), the window reader (``cat``/``trim``), the uniform grid
(``replay``/``compare``), and a rewrite to MCAP (``convert``).
"""

from __future__ import annotations

import json
import random
import struct
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from recordings import RecordingError, open_recording
from recordings.csvtext import CsvOptions
from sim.config import ConfigError, load_config
from sim.grid import GridError, align_arrays

from . import corpus

KINDS = (".mcap", ".mcap", ".h5", ".h5", ".csv", ".parquet", ".toml")
_RECORD = struct.Struct("<BQ")


@dataclass(frozen=True)
class Case:
    """One structural case: its file, what was done, the CSV encoding to read it with."""

    index: int
    path: Path
    edits: tuple[str, ...]
    encoding: str = "utf-8"

    def __str__(self) -> str:
        return f"structural case {self.index} ({self.path.suffix}: {'; '.join(self.edits)})"


def write_seeds(directory: Path) -> dict[str, bytes]:
    """The corpus's seeds and a Parquet export of its MCAP seed."""
    from recordings.convert import write_recording

    paths = corpus.write_seeds(directory)
    write_recording(open_recording(paths[".mcap"]), directory / "seed.parquet")
    paths[".parquet"] = directory / "seed.parquet"
    return {kind: path.read_bytes() for kind, path in paths.items()}


# -- MCAP -----------------------------------------------------------------------------------
def _records(data: bytes | bytearray) -> list[tuple[int, int, int]]:
    """(offset, total length, opcode) of each top-level record that fits."""
    out, pos = [], 8
    while pos + 9 <= len(data):
        opcode, length = _RECORD.unpack_from(data, pos)
        if pos + 9 + length > len(data):
            break
        out.append((pos, 9 + length, opcode))
        pos += 9 + length
    return out


def mcap_cut(rng: random.Random, data: bytearray) -> str:
    start, size, op = rng.choice(_records(data))
    at = rng.choice((start - 1, start, start + 1, start + size // 2, start + 9))
    del data[max(at, 1) :]
    return f"cut at {at} (record {op:#04x} at {start})"


def mcap_swap(rng: random.Random, data: bytearray) -> str:
    recs = _records(data)
    i = rng.randrange(len(recs) - 1)
    (a, na, _), (b, nb, _) = recs[i], recs[i + 1]
    data[a : b + nb] = data[b : b + nb] + data[a : a + na]
    return f"swap records at {a} and {b}"


def mcap_duplicate_chunk(rng: random.Random, data: bytearray) -> str:
    chunks = [r for r in _records(data) if r[2] == 0x06]
    start, size, _ = rng.choice(chunks)
    at = rng.choice([r[0] for r in _records(data)])
    data[at:at] = data[start : start + size]
    return f"chunk at {start} copied to {at}"


def mcap_footer(rng: random.Random, data: bytearray) -> str:
    footer = len(data) - 8 - 9 - 20
    field = rng.choice((0, 8))
    data[footer + 9 + field : footer + 9 + field + 8] = corpus._boundary(rng, 8)
    return f"footer field {field} set"


def mcap_repack(rng: random.Random, data: bytearray) -> str:
    """A chunk's inner records edited, the chunk re-packed with a correct size and CRC."""
    import zstandard

    chunks = [r for r in _records(data) if r[2] == 0x06]
    start, size, _ = rng.choice(chunks)
    body = start + 9
    t0, t1, _, _, comp_len = struct.unpack_from("<QQQII", data, body)
    comp = bytes(data[body + 32 : body + 32 + comp_len]).decode()
    (rec_len,) = struct.unpack_from("<Q", data, body + 32 + comp_len)
    raw = bytes(data[body + 40 + comp_len : body + 40 + comp_len + rec_len])
    inner = zstandard.ZstdDecompressor().decompress(raw) if comp == "zstd" else raw
    inner = bytearray(inner)
    marks = _records(b"\0" * 8 + inner)
    pos, length, _ = rng.choice(marks)
    pos -= 8
    what = rng.choice(("cut", "length", "field", "drop"))
    if what == "cut":
        del inner[pos + rng.choice((0, 1, length // 2)) :]
    elif what == "length":
        inner[pos + 1 : pos + 9] = corpus._boundary(rng, 8)
    elif what == "field":
        corpus._set_int(rng, inner, pos + 9 + rng.randrange(max(length - 9, 1)))
    else:
        del inner[pos : pos + length]
    packed = zstandard.ZstdCompressor().compress(bytes(inner)) if comp == "zstd" else bytes(inner)
    head = struct.pack("<QQQI", t0, t1, len(inner), zlib.crc32(inner))
    text = comp.encode()
    new = head + struct.pack("<I", len(text)) + text + struct.pack("<Q", len(packed)) + packed
    data[start : start + size] = struct.pack("<BQ", 0x06, len(new)) + new
    return f"chunk at {start}: inner record at {pos} {what}, re-packed"


def mcap_content(rng: random.Random, path: Path) -> str:
    """The seed rewritten through the writer's hooks, past its checks, with bad values."""
    from recordings.mcap_writer import McapRecordingWriter

    rec = open_recording(path)
    g = rec.gauges.copy()
    what = rng.choice(("nan", "back", "gap", "extreme", "text", "seq"))
    i = rng.randrange(1, len(g))
    if what == "nan":
        g["x_mm"][i] = rng.choice((np.nan, np.inf, -np.inf, 1e308))
    elif what == "back":
        g["t_ns"][i:] -= rng.choice((1, 10**6, 10**12))
    elif what == "gap":
        g["t_ns"][i:] += rng.choice((10**12, 2**53, 2**61))
    elif what == "extreme":
        g["t_ns"][i] = rng.choice((2**63 - 1, -(2**63)))
    elif what == "seq":
        g["seq"][i:] = rng.choice((0, 2**62, -(2**63)))
    path.unlink()
    writer = McapRecordingWriter(path, rec.metadata, plot_rate_hz=0)
    writer._write_gauges(g)  # the hooks: no checks, as a foreign writer would
    writer._write_command(rec.command)
    writer._write_drive(rec.drive)
    text = rng.choice(("x" * 1_000_000, "\x1b]0;t\x07\r\n\x00", "é" * 1000))
    writer._write_event(int(g["t_ns"][-1]) if what != "text" else 0, "note", text)
    writer.close()
    return f"rewritten with {what} at sample {i}"


# -- HDF5 -----------------------------------------------------------------------------------
def hdf5_cut(rng: random.Random, data: bytearray) -> str:
    marks = [i for sig in (b"OHDR", b"OCHK", b"GCOL", b"BTHD", b"TREE") for i in _find(data, sig)]
    at = rng.choice(marks) + rng.choice((-1, 0, 1, 4))
    del data[at:]
    return f"cut at {at} (an object header)"


def _find(data: bytearray, sig: bytes) -> list[int]:
    out, pos = [], data.find(sig)
    while pos >= 0:
        out.append(pos)
        pos = data.find(sig, pos + 1)
    return out


_META_EDITS: tuple[Callable[[dict[str, object]], None], ...] = (
    lambda m: m.__setitem__("signal", {"amplitude_mm": -1, "frequency_hz": 0, "cycles": -5}),
    lambda m: m.__setitem__("start_time_utc", "0001-01-01T00:00:00-23:59"),
    lambda m: m.__setitem__("sample_rate_hz", 1e12),
    lambda m: m.__setitem__(
        "signal", {"shape": 5, "amplitude_mm": 1, "frequency_hz": 1, "cycles": 1}
    ),
    lambda m: m.__setitem__("effects", [{"name": "x", "params": {"a": "b"}}]),
    lambda m: m.__setitem__("operator_note", "\x1b]0;t\x07" * 1000),
)


def h5py_structure(rng: random.Random, path: Path) -> str:
    with h5py.File(path, "r+") as f:
        name = rng.choice(("gauges", "command", "drive", "events"))
        what = rng.choice(("group", "external", "loop", "bigendian", "missing", "meta", "jump"))
        if what == "meta":
            meta = json.loads(f.attrs["metadata_json"])
            rng.choice(_META_EDITS)(meta)
            f.attrs["metadata_json"] = json.dumps(meta)
            return "h5py: crafted metadata_json"
        if what == "jump":
            ds = f["gauges"]
            t = ds.fields("t_ns")[...]
            t[rng.randrange(1, len(t)) :] += rng.choice((2**53, 2**62, 10**13))
            rows = ds[...]
            rows["t_ns"] = t
            ds[...] = rows
            return "h5py: gauges times jump"
        old = f[name][...]
        del f[name]
        if what == "group":
            f.create_group(name)
        elif what == "external":
            f[name] = h5py.ExternalLink("elsewhere.h5", f"/{name}")
        elif what == "loop":
            f[name] = h5py.SoftLink(f"/{name}_b")
            f[f"{name}_b"] = h5py.SoftLink(f"/{name}")
        elif what == "bigendian":
            f.create_dataset(name, data=old.astype(old.dtype.newbyteorder(">")))
        else:
            names = [n for n in old.dtype.names or () if n != "t_ns"]
            keep = [n for n in (old.dtype.names or ()) if n != rng.choice(names)]
            f.create_dataset(name, data=old[keep])
        return f"h5py: /{name} {what}"


# -- CSV, Parquet, TOML ---------------------------------------------------------------------
def csv_extreme(rng: random.Random, data: bytearray) -> str:
    text = bytes(data).decode()
    what = rng.choice(("event", "names", "twice", "bom", "utf16", "nul", "long", "endings"))
    if what == "event":
        t = rng.choice(("1e400", "-1e400", "nan", str(2**70), '"x"'))
        text = f'# labstand-event: {{"t_ns": {t}, "kind": "x", "text": 1}}\n' + text
    elif what in ("names", "twice"):
        n = rng.choice((500, 3000, 30_000))
        names = [f"c{i % (n // 2) if what == 'twice' else i}" for i in range(n)]
        text = "t_s," + ",".join(names) + "\n" + text.split("\n", 1)[1]
    elif what == "long":
        text += "1," + "9" * rng.choice((10_000, 300_000)) + "\n"
    elif what == "nul":
        text = text.replace(",", ",\x00", 3)
    elif what == "endings":
        text = text.replace("\n", rng.choice(("\r\n", "\r", "\n\r")))
    data[:] = text.encode("utf-16" if what == "utf16" else "utf-8")
    if what == "bom":
        data[:0] = b"\xef\xbb\xbf"
    return f"CSV {what}"


def parquet_edit(rng: random.Random, path: Path) -> str:
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    meta = dict(table.schema.metadata or {})
    what = rng.choice(("drive", "events", "metadata", "column", "nulls"))
    if what in ("drive", "events"):
        meta[f"labstand.{what}".encode()] = rng.choice(
            (b"[" * 100_000, b"null", b'[{"t_ns": %d}]' % 2**70, b'[{"t_ns": 1e400}]', b"{}")
        )
        table = table.replace_schema_metadata(meta)
    elif what == "metadata":
        meta[b"labstand.metadata"] = rng.choice((b"null", b"[]", b"{", b'{"schema_version": 1}'))
        table = table.replace_schema_metadata(meta)
    else:
        name = rng.choice(("t_ns", "seq", "x_mm", "flags"))
        i = table.column_names.index(name)
        n = table.num_rows
        column = pa.array(["x"] * n) if what == "column" else pa.nulls(n, pa.float64())
        table = table.set_column(i, name, column).replace_schema_metadata(meta)
    pq.write_table(table, path)
    return f"Parquet {what}"


def toml_extreme(rng: random.Random, data: bytearray) -> str:
    what = rng.choice(("dotted", "tables", "rate", "weights"))
    n = rng.choice((20, 1000, 50_000))
    if what == "dotted":
        extra = "[geometry]\n" + "a" + ".a" * n + " = 1\n"
    elif what == "tables":
        extra = "[" + ".".join(["t"] * n) + "]\nx = 1\n"
    elif what == "rate":
        extra = f"[acquisition]\nsample_rate_hz = {rng.choice(('1e12', '1e308', 'nan', '-1'))}\n"
    else:
        extra = "[weights_kg]\n" + "".join(f"w{i} = 1.0\n" for i in range(min(n, 20_000)))
    text = bytes(data).decode()
    for table in ("[geometry]", "[acquisition]", "[weights_kg]"):
        if extra.startswith(table):  # a table named twice is TOML's own refusal: avoid it
            text = text.replace(table, f"[old_{table[1:]}", 1)
    data[:] = (text + "\n" + extra).encode()
    return f"TOML {what} ({n})"


_BYTE_EDITS: dict[str, tuple[Callable[[random.Random, bytearray], str], ...]] = {
    ".mcap": (mcap_cut, mcap_swap, mcap_duplicate_chunk, mcap_footer, mcap_repack),
    ".h5": (hdf5_cut,),
    ".csv": (csv_extreme,),
    ".toml": (toml_extreme,),
}
_FILE_EDITS: dict[str, Callable[[random.Random, Path], str]] = {
    ".mcap": mcap_content,
    ".h5": h5py_structure,
    ".parquet": parquet_edit,
}
_ENCODINGS = ("utf-8", "utf-8", "utf-8", "cp1252", "hex", "rot13", "base64", "zlib", "utf-16")


def make_case(seeds: dict[str, bytes], seed: int, index: int, directory: Path) -> Case:
    """Write structural case ``index`` of ``seed`` into ``directory``."""
    rng = random.Random(f"structural/{seed}/{index}")
    kind = KINDS[index % len(KINDS)]
    path = directory / f"case{kind}"
    path.write_bytes(seeds[kind])
    edits: list[str] = []
    if kind in _FILE_EDITS and (kind not in _BYTE_EDITS or rng.random() < 0.4):
        edits.append(_FILE_EDITS[kind](rng, path))
    if kind in _BYTE_EDITS:
        data = bytearray(path.read_bytes())
        edits.append(rng.choice(_BYTE_EDITS[kind])(rng, data))
        path.write_bytes(data)
    encoding = rng.choice(_ENCODINGS) if kind == ".csv" else "utf-8"
    return Case(index, path, tuple(edits), encoding)


# -- reading --------------------------------------------------------------------------------
def read(case: Case) -> None:
    """Every read path of the commands, on the case's file."""
    from recordings.convert import write_recording
    from recordings.csvio import read_csv
    from recordings.window import read_window

    path = case.path
    if path.suffix == ".toml":
        config = load_config(path)
        for name in config.parameter_sets:
            config.stand_params(name)
        return
    if path.suffix == ".csv":
        rec = read_csv(path, options=CsvOptions(encoding=case.encoding))
        rec.check()
    else:
        windows = []
        for start, end in ((None, None), (0.1, 0.3)):
            try:
                windows.append(read_window(path, start, end))
            except RecordingError:
                windows.append(None)  # judged below by the whole read, which must agree
        try:
            rec = open_recording(path)
        except RecordingError as err:
            if windows[0] is not None:  # one validation: `cat` may not print what `info` refuses
                raise AssertionError(f"the window reader took a file info refuses: {err}") from err
            rec = open_recording(path, salvage=True)  # `labstand recover`
    frame = rec.frame()
    align_arrays(frame.index.to_numpy(), frame["x_mm"].to_numpy() * 1e-3,
                 frame["u_mm"].to_numpy() * 1e-3, frame["F_N"].to_numpy())  # fmt: skip
    write_recording(rec, path.with_name("converted.mcap"))


#: What a clean refusal raises: the readers' and the stand file's errors, the grid's.
EXPECTED = (RecordingError, ConfigError, GridError)
