"""The stand file a command uses when ``--stand`` is not given: found as at the stand.

``$LABSTAND_STAND`` (a path) first, then ``./labstand.toml``; neither: the paper's stand
(``sim.config``'s embedded default). Commands that read the stand from their recordings
(replay, play, table1, diagnose) keep doing so: a stand file lying about would otherwise
replace the one each recording was made with.
"""

from __future__ import annotations

import os
from pathlib import Path

from labstand.errors import CommandError, ExitCode

__all__ = ["ENV", "LOCAL", "find_stand"]

ENV = "LABSTAND_STAND"
LOCAL = Path("labstand.toml")


def find_stand() -> tuple[Path | None, str]:
    """The stand file to use and where it was found (``""``: none, the paper's)."""
    named = os.environ.get(ENV, "")
    if named:
        path = Path(named)
        if not path.is_file():
            why = "is a folder" if path.is_dir() else "no such file"
            raise CommandError(f"${ENV}={named}: {why}", ExitCode.USAGE)
        return path, f"${ENV}"
    if LOCAL.is_file():
        return LOCAL, "./labstand.toml"
    return None, ""
