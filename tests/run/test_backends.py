"""The backend registry: every name opens, unknown names are usage errors, and a new
backend is one module plus one line in ``BACKENDS``."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from labstand.errors import CommandError, ExitCode
from labstand.session import devices
from labstand.session.devices import BACKENDS, backend_factory
from recordings import open_recording
from tests.run.conftest import Outcome


def test_every_registered_backend_resolves_to_a_factory() -> None:
    assert set(BACKENDS) == {"stand", "sim"}
    for name in BACKENDS:
        assert callable(backend_factory(name)), name


def test_an_unknown_backend_is_a_usage_error() -> None:
    with pytest.raises(CommandError, match=r"unknown backend 'can'; one of stand, sim") as err:
        backend_factory("can")
    assert err.value.code == ExitCode.USAGE


def test_the_session_package_imports_no_backend_until_one_is_chosen() -> None:
    # the registry names modules; importing the session package must not load them
    code = (
        "import sys, labstand.session, labstand.session.devices; "
        "concrete = {'drivers.unidrive', 'drivers.unidrive_wire', 'drivers.gauge_stream'}; "
        "print(sorted(m for m in sys.modules if m in concrete or "
        "m.startswith(('labstand.backends', 'pymodbus', 'serial'))))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60
    )
    assert out.stdout.strip() == "[]"


def test_a_new_backend_is_one_module_and_one_registry_line(
    labstand: Callable[..., Outcome], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setitem(devices.BACKENDS, "thread", ("tests.run.thread_backend", "open_thread"))
    out = tmp_path / "thread.mcap"
    result = labstand(
        "run", "--backend", "thread", "--signal", "trapezoidal", "--amplitude-mm", "10",
        "--frequency-hz", "2", "--cycles", "1", "--dwell-start-s", "0.1",
        "--dwell-end-s", "0.1", "-o", out,
    )  # fmt: skip
    assert result.code == 0, result.err
    assert "thread: simulated stand in a thread: drive tcp://127.0.0.1:" in result.out
    rec = open_recording(out)
    assert len(rec.gauges) > 1000 and rec.lost_samples == 0
    assert not rec.drive["enabled"][-1]
    note = rec.events().query("kind == 'note'")["text"].iloc[-1]
    assert note.startswith("simulated stand stopped: drive disabled") and "trips []" in note
