"""The simulated gauge front end: 2 kHz binary frames computed from the stand model.

For every sample the front end takes the simulated drive's position x, advances the
stand model (``StandModel``: the baseline ``sim.model.Model`` or a model with
effects switched on), adds gauge noise, quantises to counts with the stand's calibration
and encodes ``drivers.gauge_frame`` frames with its own sequence counter and µs clock.

``PtyWriter`` sends them to a pty master without ever blocking. When nobody reads, the
pty fills (about 0.5 s of frames); whole frames are then dropped and counted, as a UART
overrun would, and the next frame sent carries the OVERRUN flag. The sequence counter
keeps counting through drops, so the reader sees the gap.
"""

from __future__ import annotations

import errno
import logging
import os
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from drivers.calibration import GaugeCalibration
from drivers.gauge_frame import FRAME_SIZE, FrameFlag, encode_frames

FloatArray = NDArray[np.float64]
log = logging.getLogger(__name__)

__all__ = ["FrontEndSettings", "GaugeFrontEnd", "PtyWriter", "StandModel"]


class StandModel(Protocol):
    """What the front end needs from the physics: u and F for the next drive positions."""

    def advance(self, x_m: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Weight displacement u (m) and fibre force F (N) at the next len(x_m) samples."""
        ...


@dataclass(frozen=True)
class FrontEndSettings:
    """The simulated front end ([estimate] unless said otherwise).

    Attributes
    ----------
    rate_hz
        Frame rate, Hz (2 kHz [paper]).
    force_noise_n
        Standard deviation of the force gauge's noise, N.
    weight_noise_mm
        Standard deviation of the displacement gauge's noise, mm.
    seed
        Noise generator seed (None: fresh each run).
    seq_start
        First sequence number (tests start near 65535 to see the wrap).
    clock_start_us
        Device clock at the first frame, µs (tests start near 2³² to see the wrap).
    """

    rate_hz: float = 2000.0
    force_noise_n: float = 0.02
    weight_noise_mm: float = 0.0005
    seed: int | None = 0
    seq_start: int = 0
    clock_start_us: int = 0


class SampleTap(Protocol):
    """Receives each block the front end measures: seq, device µs, x mm, u mm, F N, flags."""

    def __call__(
        self,
        seq: NDArray[np.int64],
        t_us: NDArray[np.int64],
        x_mm: FloatArray,
        u_mm: FloatArray,
        force_n: FloatArray,
        flags: NDArray[np.uint8],
    ) -> None: ...


class GaugeFrontEnd:
    """Turns drive positions into frames, sample by sample."""

    def __init__(
        self,
        model: StandModel,
        calibration: GaugeCalibration,
        settings: FrontEndSettings | None = None,
    ) -> None:
        self.model = model
        self.calibration = calibration
        self.settings = settings or FrontEndSettings()
        self._rng = np.random.default_rng(self.settings.seed)
        self.produced = 0  # frames produced (sent or dropped)
        self.overrun_pending = False
        #: Called with every block the front end measures, before it is framed (for a
        #: live view of the simulated stand; ``labstand stand-sim --foxglove``).
        self.tap: SampleTap | None = None

    def frames(self, x_m: FloatArray) -> bytes:
        """Frames for the next len(x_m) samples (x downward positive, m)."""
        n = len(x_m)
        if n == 0:
            return b""
        s = self.settings
        u_m, force_n = self.model.advance(x_m)
        force = force_n + self._rng.normal(0.0, s.force_noise_n, n) if s.force_noise_n else force_n
        u_mm = u_m * 1e3
        if s.weight_noise_mm:
            u_mm = u_mm + self._rng.normal(0.0, s.weight_noise_mm, n)
        counts = self.calibration.to_counts(force, u_mm, np.asarray(x_m) * 1e3)
        idx = self.produced + np.arange(n, dtype=np.int64)
        seq = s.seq_start + idx
        # The device clock counts whole µs of its own crystal: i·(1e6/rate), not summed.
        t_us = s.clock_start_us + (idx * 1_000_000) // round(s.rate_hz)
        flags = np.zeros(n, dtype=np.uint8)
        if self.overrun_pending:
            flags[0] |= FrameFlag.OVERRUN
            self.overrun_pending = False
        self.produced += n
        if self.tap is not None:
            self.tap(seq, t_us, np.asarray(x_m) * 1e3, u_mm, force, flags)
        return encode_frames(seq, t_us, *counts, flags=flags)


class PtyWriter:
    """Non-blocking writer of whole frames to a pty master, dropping what does not fit."""

    def __init__(self, fd: int) -> None:
        self.fd = fd
        self._partial = b""  # the tail of a frame the pty took only in part
        self.sent = 0  # frames
        self.dropped = 0  # frames

    def write(self, data: bytes) -> int:
        """Send frames; returns how many were dropped because the pty was full."""
        if self._partial:
            n = self._write(self._partial)
            self._partial = self._partial[n:]
            if self._partial:  # still full: everything new is dropped
                dropped = len(data) // FRAME_SIZE
                self.dropped += dropped
                return dropped
        n = self._write(data)
        whole, part = divmod(n, FRAME_SIZE)
        if part:  # finish this frame later, like a UART finishing the byte it shifts out
            self._partial = data[n : n + FRAME_SIZE - part]
            whole += 1
        self.sent += whole
        dropped = len(data) // FRAME_SIZE - whole
        self.dropped += dropped
        if dropped:
            log.debug("gauge pty full: %d frames dropped", dropped)
        return dropped

    def inject(self, data: bytes) -> bool:
        """Send raw bytes between two whole frames (fault injection: line noise).

        Returns False, sending nothing, while a frame is still half sent; what the pty
        does not take is lost, like noise on a line nobody listens to.
        """
        if self._partial:
            return False
        self._write(data)
        return True

    def _write(self, data: bytes) -> int:
        try:
            return os.write(self.fd, data)
        except BlockingIOError:
            return 0
        except OSError as err:
            if err.errno in {errno.EAGAIN, errno.EIO}:
                return 0
            raise
