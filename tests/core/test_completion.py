"""``labstand completion bash``: the script completes commands, options and file names
in a real bash."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest


def complete(script: Path, cwd: Path, *words: str) -> list[str]:
    quoted = " ".join(f"'{w}'" for w in words)
    program = (
        f"source {script}; COMP_WORDS=(labstand {quoted}); COMP_CWORD={len(words)}; "
        '_shtab_labstand; printf "%s\\n" "${COMPREPLY[@]}"'
    )
    done = subprocess.run(
        ["bash", "-c", program], capture_output=True, text=True, cwd=cwd, check=True
    )
    return sorted(done.stdout.split())


@pytest.mark.skipif(shutil.which("bash") is None, reason="no bash")
def test_bash_completes_commands_options_and_files(tmp_path: Path) -> None:
    script = tmp_path / "labstand.bash"
    done = subprocess.run(
        [sys.executable, "-m", "labstand", "completion", "bash"],
        capture_output=True,
        text=True,
        check=True,
    )
    script.write_text(done.stdout)
    (tmp_path / "run-1.mcap").write_bytes(b"")
    (tmp_path / "run-2.h5").write_bytes(b"")
    assert complete(script, tmp_path, "di") == ["diagnose", "diagnose-check"]
    assert complete(script, tmp_path, "run", "--op") == ["--operator"]
    assert complete(script, tmp_path, "info", "run-") == ["run-1.mcap", "run-2.h5"]
    assert complete(script, tmp_path, "diagnose-check", "--truth", "") == [
        "other",
        "outside",
        "same",
    ]
