"""The simulated stand's measurements to the live view (``labstand stand-sim --foxglove``).

``FrontEndTap`` is the simulated gauge front end's ``tap``: each block it measures
(before framing) becomes a gauges block on the feed, its time counted from the first
sample. The model beside it is the baseline; with an effect switched on in the
simulated stand, the residual shows what the baseline lacks.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from labstand.live.feed import LiveFeed
from recordings.schema import COMMAND_DTYPE, GAUGES_DTYPE

__all__ = ["FrontEndTap"]

_NO_COMMAND = np.zeros(0, dtype=COMMAND_DTYPE)  # stand-sim has no planned motion to show


class FrontEndTap:
    """Offers what the simulated front end measures to a ``LiveFeed`` (never blocks)."""

    def __init__(self, feed: LiveFeed) -> None:
        self.feed = feed
        self._t0_us: int | None = None

    def __call__(
        self,
        seq: NDArray[np.int64],
        t_us: NDArray[np.int64],
        x_mm: NDArray[np.float64],
        u_mm: NDArray[np.float64],
        force_n: NDArray[np.float64],
        flags: NDArray[np.uint8],
    ) -> None:
        """One measured block."""
        if self._t0_us is None:
            self._t0_us = int(t_us[0])
        block = np.empty(len(seq), dtype=GAUGES_DTYPE)
        block["seq"], block["t_ns"] = seq, (t_us - self._t0_us) * 1000
        block["x_mm"], block["u_mm"], block["force_n"], block["flags"] = x_mm, u_mm, force_n, flags
        self.feed.offer_gauges(block, _NO_COMMAND)
