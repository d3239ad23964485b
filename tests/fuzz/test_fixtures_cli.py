"""The malformed files a mutation campaign found, through the real ``labstand`` command.

Each one used to end in a traceback or a hang (tests/fixtures/fuzz/README.md says how);
now each must end in one line naming the file and its fault, exit 2, and leave no output.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXE = Path(sys.executable).with_name("labstand")
FIXTURES = Path(__file__).parents[1] / "fixtures" / "fuzz"
TIMEOUT_S = 60  # generous: a busy machine; a hang used to run for ever

#: file -> what the one line must say (the fault, not a symptom)
FAULTS = {
    "hdf5_attr_void.h5": "attribute metadata_json must be text",
    "hdf5_hang_1.h5": "global heap collection at byte 2048 is damaged: object 0 at byte 5086",
    "hdf5_hang_2.h5": "global heap collection at byte 2048 is damaged: object 0 at byte 4376",
    "hdf5_huge_shape.h5": "dataset /gauges has shape (100000000000,), larger than the file",
    "hdf5_keyerror.h5": "damaged HDF5 file: Unable to synchronously open object (incorrect "
    "metadata checksum",
    "hdf5_oserror.h5": "dataset /command cannot be read",
    "hdf5_schema_array.h5": "attribute schema_version is an array of shape (2,)",
    "mcap_endoffile.mcap": "record 0x06 at byte 52526 does not decode: it ends before",
    "mcap_meta_bigint.mcap": "the summary section is damaged: the footer puts the summary",
    "tdms_memory.tdms": "not a readable TDMS file: a segment's metadata is cut short",
    "tdms_struct_error.tdms": "not a readable TDMS file: a segment's metadata is cut short",
    "tdms_scaling_keyerror.tdms": "channel 'Run/Force' has a broken NI scaling: no property "
    "'NI_Scale[0]_Polynomial_Coefficients[0]'",
    "tdms_start_time_string.tdms": "channel 'Run/Drive' property wf_start_time is 'yesterday'",
    "toml_bigint.toml": "[drive] speed_max_m_s: must be a number in range",
    "toml_deep_array.toml": "line 2: arrays or tables nested deeper than 16 levels",
    "toml_weights_scalar.toml": "[weights_kg] must be a table, got 5",
}


def _command(path: Path, out_dir: Path) -> tuple[list[str], Path | None]:
    """The command the README names for the file's kind, and the output it must not leave."""
    if path.suffix in (".h5", ".mcap"):
        return ["info", str(path)], None
    if path.suffix == ".tdms":
        out = out_dir / "x.h5"
        return ["import", str(path), "-o", str(out)], out
    out = out_dir / "x.csv"
    return ["simulate", "--situation", "11", "--stand", str(path), "-o", str(out)], out


def test_every_fixture_has_a_case() -> None:
    on_disk = {p.name for p in FIXTURES.iterdir() if p.name != "README.md"}
    assert on_disk == set(FAULTS)


@pytest.mark.timeout(2 * TIMEOUT_S)
@pytest.mark.parametrize("name", sorted(FAULTS))
def test_malformed_file_is_one_line_exit_2(name: str, tmp_path: Path) -> None:
    path = FIXTURES / name
    args, out = _command(path, tmp_path)
    res = subprocess.run(
        [str(EXE), *args],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        cwd=tmp_path,
        check=False,
    )
    lines = res.stderr.splitlines()
    assert "Traceback" not in res.stderr
    assert res.returncode == 2, res.stderr
    assert len(lines) == 1, res.stderr
    assert lines[0].startswith(f"labstand: error: {path}: "), lines[0]
    assert FAULTS[name] in lines[0]
    assert out is None or not out.exists()
