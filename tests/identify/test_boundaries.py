"""The diagnosis is identification on arrays: it loads no hardware and no file format."""

from __future__ import annotations

import json
import subprocess
import sys

FORBIDDEN = ("pymodbus", "serial", "sim.hardware", "h5py", "mcap", "nptdms", "recordings")


def test_the_fitter_and_the_diagnosis_load_no_modbus_server_and_no_file_format() -> None:
    code = (
        "import json, sys\n"
        "import sim.identify, sim.checks.check, sim.identify.fitting\n"
        f"bad = [m for m in sys.modules if m.split('.')[0] in {FORBIDDEN!r} "
        f"or m.startswith({FORBIDDEN!r})]\n"
        "print(json.dumps(sorted(bad)))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert json.loads(out.stdout) == []


def test_importing_the_effects_registers_nothing_anywhere() -> None:
    # The registry is a dict; the simulated stand finds effects there, not by import side
    # effects (the old plug-in registration ran when sim.effects was imported).
    code = (
        "import sys\n"
        "import sim.effects\n"
        "print('sim.hardware' in sys.modules, 'sim.hardware.stand_model' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.split() == ["False", "False"]
