"""Every written format reads back: a real ``run --backend sim`` recording converted
through every pair of formats (A → B) says the same through ``info``, ``cat``,
``replay`` and (one pair) ``diagnose`` as the recording it came from."""

from __future__ import annotations

import contextlib
import functools
import io
import json
from itertools import product
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from labstand.cli import main
from recordings import open_recording
from tests.run.conftest import SHORT, labstand_process

FORMATS = (".mcap", ".h5", ".csv", ".parquet")


def labstand(*args: str | Path) -> str:
    """The command in this process (its stdout); the pairs are many, start-ups slow."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    assert code == 0, f"labstand {' '.join(map(str, args))}: {err.getvalue()}"
    return out.getvalue()


@functools.cache
def said(command: str, path: Path, *options: str) -> str:
    """What the source recording says (asked once for all pairs)."""
    return labstand(command, path, *options)


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The run (MCAP) and its conversion into every format (the A of each pair)."""
    folder = tmp_path_factory.mktemp("pairs")
    run = folder / "run.mcap"
    who = ["--operator", "ana", "--sample", "F-07", "--tag", "warm", "--tag", "x"]
    done = labstand_process("run", *SHORT, "--note", "pairs", *who, "-o", run)
    assert done.code == 0, done.err
    out = {".mcap": run}
    for suffix in FORMATS[1:]:
        out[suffix] = folder / f"a{suffix}"
        labstand("convert", run, out[suffix])
    return out


def _info(path: Path, ask: Any = labstand) -> dict[str, Any]:
    info = json.loads(ask("info", path, "--json"))
    info.pop("path")
    return info


def _replay(path: Path, ask: Any = labstand) -> dict[str, Any]:
    out = json.loads(ask("replay", path, "--json"))
    out.pop("recording")
    return out


@pytest.mark.parametrize(("a", "b"), list(product(FORMATS, FORMATS)))
def test_a_pair_reads_back(made: dict[str, Path], tmp_path: Path, a: str, b: str) -> None:
    source = made[".mcap"]
    target = tmp_path / f"b{b}"
    labstand("convert", made[a], target)
    want, got = open_recording(source), open_recording(target)
    np.testing.assert_array_equal(got.gauges, want.gauges)
    np.testing.assert_array_equal(got.drive, want.drive)
    assert got.events_array.tolist() == want.events_array.tolist()
    np.testing.assert_array_equal(got.command_on_gauge_clock(), want.command_on_gauge_clock())
    assert got.metadata.to_dict() == want.metadata.to_dict()
    meta = got.metadata  # the run's structured metadata, in every format
    assert (meta.operator, meta.sample, meta.tags) == ("ana", "F-07", ("warm", "x"))
    assert len(meta.run_id) == 36
    assert _info(target) == _info(source, said)
    assert labstand("cat", target) == said("cat", source)
    assert labstand("cat", target, "--events") == said("cat", source, "--events")
    assert _replay(target) == _replay(source, said)


def test_diagnose_reads_a_converted_pair_alike(made: dict[str, Path], tmp_path: Path) -> None:
    target = tmp_path / "b.csv"
    labstand("convert", made[".parquet"], target)

    def diagnosis(path: Path) -> dict[str, Any]:
        # The remainder's drift terms name their recording: the same for both files.
        out = json.loads(labstand("diagnose", path, "--json").replace(path.name, "REC"))
        # Where the answer came from differs by construction (each file's hash and size,
        # the time it was made); what it says must not.
        for key in ("timings_s", "recordings", "mass_kg", "provenance"):
            out.pop(key)
        return out

    assert diagnosis(target) == diagnosis(made[".mcap"])
