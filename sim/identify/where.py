"""Where the gap lies: shares of the residual by channel, phase, regime and frequency band.

Every share is of the normalised squared residual (the residual of each channel divided
by the recorded channel's spread, so u in mm and F in N weigh alike), summed over all
traces; shares within one breakdown add up to 1.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import NDArray

from sim.identify.traces import PHASES, Trace

FloatArray = NDArray[np.float64]

REGIMES = ("taut", "slack", "snatch", "sticking")
#: After the fibre re-tensions, the snatch regime lasts this long, s.
SNATCH_S = 0.03
#: Taut and the weight slower than this: sticking (or nearly), m/s.
STICK_SPEED_M_S = 2e-3
BANDS_HZ = ((0.0, 2.0), (2.0, 20.0), (20.0, 100.0), (100.0, float("inf")))
CHANNELS = ("u", "F")


@dataclass(frozen=True)
class SimStates:
    """What the fitted baseline says about each sample of a trace."""

    u_m: FloatArray
    force_n: FloatArray
    v_m_s: FloatArray

    @classmethod
    def of(cls, u_m: FloatArray, force_n: FloatArray, rate_hz: float) -> SimStates:
        """A model's states from its outputs, u's rate by finite differences.

        The outputs as the fit saw them (restarted from measured states): an open-loop run
        of a chaotic light-weight recording would attribute chaos.
        """
        return cls(u_m, force_n, np.gradient(u_m, 1.0 / rate_hz))


def regimes(states: SimStates, rate_hz: float) -> NDArray[np.int64]:
    """Regime index per sample (REGIMES order)."""
    slack = states.force_n <= 0.0
    regime = np.zeros(slack.size, dtype=np.int64)
    regime[np.abs(states.v_m_s) < STICK_SPEED_M_S] = 3
    regime[slack] = 1
    retension = np.flatnonzero(slack[:-1] & ~slack[1:]) + 1
    width = max(1, int(SNATCH_S * rate_hz))
    for start in retension:
        window = regime[start : start + width]
        window[window != 1] = 2
    return regime


def _band_energy(residual: FloatArray, rate_hz: float) -> FloatArray:
    spectrum = np.abs(np.fft.rfft(residual)) ** 2
    freqs = np.fft.rfftfreq(residual.size, 1.0 / rate_hz)
    return np.array([spectrum[(freqs >= lo) & (freqs < hi)].sum() for lo, hi in BANDS_HZ])


def _shares(energy: dict[str, float]) -> dict[str, float]:
    total = sum(energy.values())
    return {k: (v / total if total > 0 else 0.0) for k, v in energy.items()}


@dataclass(frozen=True)
class Where:
    """Shares of the fitted baseline's normalised squared residual (each breakdown sums to 1).

    ``phase``, ``regime`` and ``band`` are per channel (``u``, ``F``).
    """

    channel: dict[str, float]
    phase: dict[str, dict[str, float]]
    regime: dict[str, dict[str, float]]
    band: dict[str, dict[str, float]]
    time_in_regime_s: dict[str, float]

    def to_dict(self) -> dict[str, object]:
        """JSON keys channel, phase, regime, band, time_in_regime_s."""
        return asdict(self)


def where_the_gap_lies(traces: Sequence[Trace], states: Sequence[SimStates]) -> Where:
    """The breakdowns for the residual of the fitted baseline (see module docstring)."""
    by_channel = dict.fromkeys(CHANNELS, 0.0)
    by_phase = {c: dict.fromkeys(PHASES, 0.0) for c in CHANNELS}
    by_regime = {c: dict.fromkeys(REGIMES, 0.0) for c in CHANNELS}
    by_band = {c: dict.fromkeys(_band_names(), 0.0) for c in CHANNELS}
    time_in_regime = dict.fromkeys(REGIMES, 0.0)
    for tr, st in zip(traces, states, strict=True):
        ok = tr.present
        reg = regimes(st, tr.rate_hz)
        for k, name in enumerate(REGIMES):
            time_in_regime[name] += float(np.count_nonzero(reg == k)) / tr.rate_hz
        for channel, rec, sim in (("u", tr.u_m, st.u_m), ("F", tr.force_n, st.force_n)):
            spread = float(np.linalg.norm(rec[ok] - rec[ok].mean())) or 1.0
            r = np.where(ok, sim - rec, 0.0) / spread
            e = r**2
            by_channel[channel] += float(e.sum())
            for k, name in enumerate(PHASES):
                by_phase[channel][name] += float(e[tr.phase == k].sum())
            for k, name in enumerate(REGIMES):
                by_regime[channel][name] += float(e[reg == k].sum())
            for name, value in zip(_band_names(), _band_energy(r, tr.rate_hz), strict=True):
                by_band[channel][name] += float(value)
    return Where(
        channel=_shares(by_channel),
        phase={c: _shares(v) for c, v in by_phase.items()},
        regime={c: _shares(v) for c, v in by_regime.items()},
        band={c: _shares(v) for c, v in by_band.items()},
        time_in_regime_s=time_in_regime,
    )


def _band_names() -> list[str]:
    return [f"{lo:g}-{hi:g} Hz" if np.isfinite(hi) else f">{lo:g} Hz" for lo, hi in BANDS_HZ]
