"""The fibre jumping between two seats on the pulley after slack episodes.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sim.effects.info import EffectInfo, Measured, param

FloatArray = NDArray[np.float64]


def _slack_n(row: FloatArray) -> float:
    # Slack: the force below 5 % of the rest tension, well above the gauge's noise and hum
    # (tenths of a newton) and far below a taut fibre's force.
    from sim.physics import layout  # the registry's columns (it imports this module)

    return float(0.05 * row[layout.P_GRAVITY_N] / row[layout.P_PROJ])


def _seats_at(row: FloatArray, measured: Measured, at: NDArray[np.int64]) -> FloatArray:
    """``kernel.measured_seats``: the seat state (I_LOFF … I_SLACKT) at samples ``at``."""
    from sim.physics import compose  # numba, loaded when a run needs it

    seats = compose.union().measured_seats(
        row, measured.x_rel_m, measured.u_m, measured.force_n, 1.0 / measured.rate_hz,
        _slack_n(row), at,
    )  # fmt: skip
    return np.asarray(seats, dtype=np.float64)


def _start_state(
    row: FloatArray, measured: Measured, starts: NDArray[np.int64], init: FloatArray
) -> None:
    # The seat follows the recorded slack episodes (``kernel.measured_seats``).
    from sim.physics import layout

    init[:, layout.I_LOFF : layout.I_SLACKT + 1] = _seats_at(row, measured, starts)


def recorded_seat(row: FloatArray, measured: Measured) -> FloatArray:
    """The seat's offset at every sample, as the recorded slack episodes put it (m).

    What a segment's run holds the seat at (``kernel._advance``), rather than letting it
    follow the model's own slack: where the simulated episodes' lengths straddle a dwell
    threshold that the recorded ones clear or miss cleanly, the seat goes wrong inside
    segments (val_15: closure 0.58 with the model's slack inside runs, 0.82 with this).
    """
    every = np.arange(measured.x_rel_m.size, dtype=np.int64)
    return np.ascontiguousarray(_seats_at(row, measured, every)[:, 0])


# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "fibre_pulley_jump", "physical",
    "once the slack is onset_m deep and has lasted dwell_s the fibre leaves its groove and "
    "re-seats in the next seat (the other of two grooves, or one step up the flank, up to "
    "seats steps), changing the effective length by "
    "step_m·(1 − exp(−(slack depth − onset_m)/depth_scale_m)) per step",
    "offset steps in force and position right after slack episodes",
    "PJ",
    (
        param("step_m", "m", 2.0e-4, (1.0e-4, 5.0e-4), (-1.0e-2, 1.0e-2), "STEP",
              "length change of the second seat (+: effective fibre shorter)", log=True,
              bounds=(-3.0e-3, 3.0e-3),
              why="re-seating across an 80 mm pulley's groove or onto its flange changes the "
                  "fibre path by up to a few millimetres, either way"),
        param("depth_scale_m", "m", 1.0e-3, (5.0e-4, 5.0e-3), (1.0e-6, 0.1), "DEPTH",
              "slack depth over which the fibre completes its jump", log=True,
              bounds=(1.0e-5, 3.0e-2),
              why="from a snap (a hundredth of a millimetre of further slack) to a slow "
                  "slide over a loop as high as the flange (a few cm)"),
        param("onset_m", "m", 0.0, (0.0, 1.0e-3), (0.0, 0.05), "ONSET",
              "slack depth at which the fibre leaves its groove", bounds=(0.0, 5.0e-3),
              why="a fibre held in its groove by friction leaves it only once its loop is "
                  "as deep as the groove or the flange: 0 to a few millimetres"),
        param("dwell_s", "s", 0.0, (0.0, 0.05), (0.0, 1.0), "DWELL",
              "time the fibre lies slack before it leaves its groove", bounds=(0.0, 0.2),
              why="a loose loop slides out of a groove a few millimetres deep under its own "
                  "weight and the groove's friction within tens of milliseconds "
                  "(free fall over 1–10 mm takes 14–45 ms); at once when it is flicked out",
              # 0, then 2 ms to 0.2 s in steps of 20 %: finer than the spread of the
              # slack episodes' lengths (tens of ms) the threshold must fall between.
              scan=(0.0, *(float(v) for v in np.geomspace(2.0e-3, 0.2, 26)))),
        param("seats", "1", 0.0, (0.0, 0.0), (0.0, 20.0), "SEATS",
              "0: the fibre toggles between two grooves; n ≥ 1: each episode moves it one "
              "step_m further up the groove's flank, up to n steps (the flange), where it "
              "stays", drawn=False, bounds=(0.0, 8.0), integer=True, scan=tuple(range(9)),
              why="a pulley with two grooves (or a groove and its flange) toggles; a single "
                  "groove 1–2 mm deep lets a fibre climb its flank in a few steps of "
                  "0.1–2 mm before the flange stops it"),
    ),
    start_state=_start_state,
    # Richer forms: more seats, a creeping seat: a force with position, a slow u offset.
    richer=(("position", "u+F"), ("drift", "u")),
    data_starts="sim.effects.fibre_pulley_jump.seat_probe:seat_probes",
    read_again=True,
)
# fmt: on
