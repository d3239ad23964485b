"""Plain CSV runs: header ``t_s,x_mm,u_mm,F_N``."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

HEADER = "t_s,x_mm,u_mm,F_N"


def write_csv(
    path: Path,
    t_s: NDArray[np.float64],
    x_mm: NDArray[np.float64],
    u_mm: NDArray[np.float64],
    force_n: NDArray[np.float64],
) -> None:
    """Write the four columns; written to a temporary name first, so a crash leaves no stub."""
    table = np.column_stack([t_s, x_mm, u_mm, force_n])
    tmp = path.with_name(path.name + ".part")
    np.savetxt(tmp, table, delimiter=",", header=HEADER, comments="", fmt="%.9g")
    os.replace(tmp, path)
