"""``labstand plot REC``: a PNG beside the recording, its data the recording's."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

from labstand.cli import main
from labstand.recording_plot import recording_figure
from recordings import open_recording


def test_plot_writes_a_png_of_the_recording(tmp_path: Path) -> None:
    rec_path = tmp_path / "s11.h5"
    assert main(["simulate", "--situation", "11", "-o", str(rec_path)]) == 0
    argv = [sys.executable, "-m", "labstand", "plot", str(rec_path)]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    png = tmp_path / "s11.png"
    assert done.stdout == f"wrote {png} (8001 samples, t = 0 … 4 s)\n"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    again = subprocess.run(argv, capture_output=True, text=True, timeout=120, check=False)
    assert again.returncode == 2 and "s11.png: exists" in again.stderr

    rec = open_recording(rec_path)
    fig = recording_figure(rec, "t")
    x, u, f = (ax.get_lines()[0] for ax in fig.axes)
    np.testing.assert_array_equal(u.get_ydata(), rec.gauges["u_mm"])
    np.testing.assert_array_equal(f.get_ydata(), rec.gauges["force_n"])
    np.testing.assert_array_equal(x.get_xdata(), rec.gauges["t_ns"] / 1e9)
    events = [line for line in fig.axes[2].get_lines()[1:]]  # one line per event
    assert len(events) == len(rec.events_array) == 2
