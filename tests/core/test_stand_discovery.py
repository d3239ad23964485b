"""The stand file without ``--stand``: ``$LABSTAND_STAND``, then ``./labstand.toml``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

STAND = '[weights_kg]\nlab = 5.0\n\n[weight]\ndefault = "lab"\n'
OTHER = '[weights_kg]\nlab2 = 6.5\n\n[weight]\ndefault = "lab2"\n'
SIGNAL = ["--signal", "trapezoidal", "--amplitude-mm", "20", "--frequency-hz", "1"]


def simulate(cwd: Path, env: dict[str, str], *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "labstand", "simulate", *SIGNAL, *extra],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        cwd=cwd,
        env=env,
    )


def test_found_in_the_environment_then_the_folder(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "LABSTAND_STAND"}
    assert ", m = 8.131 kg " in simulate(tmp_path, env).stdout  # none: the paper's stand
    (tmp_path / "labstand.toml").write_text(STAND)
    assert ", m = 5 kg " in simulate(tmp_path, env).stdout
    other = tmp_path / "other.toml"
    other.write_text(OTHER)
    assert ", m = 6.5 kg " in simulate(tmp_path, {**env, "LABSTAND_STAND": str(other)}).stdout
    flag = simulate(tmp_path, {**env, "LABSTAND_STAND": str(other)}, "--stand", "labstand.toml")
    assert ", m = 5 kg " in flag.stdout  # the flag wins
    missing = simulate(tmp_path, {**env, "LABSTAND_STAND": str(tmp_path / "nope.toml")})
    assert missing.returncode == 2
    assert (
        missing.stderr
        == f"labstand: error: $LABSTAND_STAND={tmp_path / 'nope.toml'}: no such file\n"
    )
