"""Writes a recording as fast as it can until killed; prints the last sample handed over.

Run by test_kill.py as ``python kill_worker.py OUT.{mcap,h5}``. After every write call
returns it prints ``G <t_ns>``: the recording must hold everything up to the last such
line minus at most 1 s, whenever the process is killed.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from recordings import COMMAND_DTYPE, DRIVE_DTYPE, GAUGES_DTYPE, make_metadata, open_writer
from sim.config import default_config

BLOCK = 100  # 50 ms at 2 kHz, like the acquisition's writer thread
DT_NS = 500_000


def main() -> None:
    path = Path(sys.argv[1])
    meta = make_metadata(default_config().to_dict(), "sim", operator_note="kill test")
    writer = open_writer(path, meta)
    writer.write_event(0, "start", "kill test")
    print("S 0", flush=True)
    i = 0
    while True:
        index = np.arange(i, i + BLOCK)
        g = np.zeros(BLOCK, GAUGES_DTYPE)
        g["seq"], g["t_ns"] = index, index * DT_NS
        g["x_mm"] = np.sin(index * 1e-3)
        g["u_mm"], g["force_n"] = 0.5 * g["x_mm"], 45.0 + np.cos(index * 1e-2)
        c = np.zeros(BLOCK, COMMAND_DTYPE)
        c["t_ns"], c["x_cmd_mm"] = g["t_ns"], g["x_mm"]
        writer.write_gauges(g)
        writer.write_command(c)
        if (i // BLOCK) % 2 == 0:  # 20 Hz drive polls
            d = np.zeros(1, DRIVE_DTYPE)
            d["t_ns"], d["position_mm"], d["enabled"] = g["t_ns"][0], g["x_mm"][0], True
            writer.write_drive_state(d)
        i += BLOCK
        print(f"G {int(g['t_ns'][-1])}", flush=True)


if __name__ == "__main__":
    main()
