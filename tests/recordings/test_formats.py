"""The formats table: every suffix read in a fresh interpreter, loading only its own library."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from nptdms import ChannelObject, TdmsWriter

from recordings import RecordingMetadata, open_recording, open_writer
from recordings.catalog import HEADS
from recordings.convert import write_recording
from recordings.formats import FORMATS, suffixes
from tests.recordings.conftest import command, gauges

#: What docs/recording-format.md promises to read (a format the table forgets fails here).
SUFFIXES = (".csv", ".h5", ".hdf5", ".mcap", ".parquet", ".tdms")
N = 4000  # 2 s at 2 kHz
#: The third-party library that only its own format may load.
LIBRARY = {".mcap": "mcap", ".h5": "h5py", ".hdf5": "h5py", ".tdms": "nptdms"}
LIBRARY[".parquet"] = "pyarrow"
#: Loaded by none of the readers: the optimiser (the fits), numba (the model).
NEVER = ("scipy.optimize", "numba")


def _stream(path: Path, meta: RecordingMetadata) -> None:
    with open_writer(path, meta) as w:
        w.write_gauges(gauges(N))
        w.write_command(command(N))


def _tdms(path: Path, meta: RecordingMetadata) -> None:
    wf = {"wf_increment": 0.0005, "wf_start_offset": 0.0}
    g = gauges(N)
    with TdmsWriter(path) as writer:
        writer.write_segment(
            [
                ChannelObject("Run", name, g[field].astype(np.float64), properties=wf)
                for name, field in (("x_mm", "x_mm"), ("u_mm", "u_mm"), ("F_N", "force_n"))
            ]
        )


def _maker(suffix: str) -> Callable[[Path, RecordingMetadata], None]:
    """How a test file of ``suffix`` is made: by our writer, else from the table (convert)."""
    if suffix == ".tdms":  # foreign: made by npTDMS itself
        return _tdms
    if FORMATS[suffix].writer:
        return _stream

    def table(path: Path, meta: RecordingMetadata) -> None:
        source = path.with_suffix(".source.mcap")
        _stream(source, meta)
        write_recording(open_recording(source), path)

    return table


_READ = """
import json, sys
from recordings import open_recording
rec = open_recording(sys.argv[1])
loaded = [m for m in {names!r} if m in sys.modules]
print(json.dumps({{"samples": len(rec.gauges), "x0": float(rec.gauges["x_mm"][1]),
                   "loaded": loaded}}))
"""


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_every_suffix_reads_in_a_fresh_interpreter_loading_only_its_own_library(
    tmp_path: Path, meta: RecordingMetadata, suffix: str
) -> None:
    # A fresh interpreter: nothing imported by another test can stand in for a format
    # module that the table fails to name (no reader can be forgotten).
    path = tmp_path / f"run{suffix}"
    _maker(suffix)(path, meta)
    names = sorted({*LIBRARY.values(), *NEVER})
    out = subprocess.run(
        [sys.executable, "-c", _READ.format(names=names), str(path)],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout)
    assert got["samples"] == N
    assert got["x0"] == pytest.approx(float(gauges(N)["x_mm"][1]))
    own = {LIBRARY[suffix]} if suffix in LIBRARY else set()
    if suffix in (".csv", ".parquet"):  # pandas 3 imports pyarrow itself
        own |= set(_loaded_by("pandas", names))
    assert sorted(got["loaded"]) == sorted(own)


def _loaded_by(module: str, names: list[str]) -> list[str]:
    """Which of ``names`` importing ``module`` alone loads, in a fresh interpreter."""
    code = f"import sys, {module}; print(' '.join(m for m in {names!r} if m in sys.modules))"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    return out.stdout.split()


def test_importing_recordings_and_its_table_loads_no_format_library() -> None:
    code = (
        "import sys\n"
        "import recordings, recordings.formats, recordings.recording, recordings.base\n"
        "from recordings import open_recording, open_writer\n"
        "heavy = ('h5py', 'mcap', 'nptdms', 'pyarrow', 'pandas', 'scipy', 'numba')\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.strip() == "[]"


def test_every_reader_and_writer_the_table_names_exists() -> None:
    assert sorted(FORMATS) == list(SUFFIXES)
    for suffix, fmt in FORMATS.items():
        assert fmt.reader, f"{suffix}: every format is read"
        for role in ("read", "write", "table"):
            if fmt.target(role):
                assert callable(fmt.load(role)), (suffix, role)


def test_ls_knows_the_metadata_of_every_format_labstand_writes() -> None:
    assert (
        sorted(HEADS) == suffixes("write", "table") == [".csv", ".h5", ".hdf5", ".mcap", ".parquet"]
    )


def test_the_table_cannot_be_changed_by_importing_a_module() -> None:
    with pytest.raises(TypeError):
        FORMATS[".xyz"] = FORMATS[".mcap"]  # type: ignore[index]
