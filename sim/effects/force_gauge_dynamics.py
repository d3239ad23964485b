"""The force gauge and its amplifier: a second-order low-pass.

Output transform: ``sim.effects.measure`` (one chain for the three gauge effects, in
physical order); equations: docs/effects.md.
"""

from __future__ import annotations

from sim.effects.info import EffectInfo, param

# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "force_gauge_dynamics", "measurement",
    "the force gauge and amplifier: second-order low-pass ω²/(s² + 2ζωs + ω²)",
    "force peaks attenuated and delayed; displacement unaffected",
    "FG",
    (
        param("cutoff_hz", "Hz", 80.0, (30.0, 300.0), (1.0, 1.0e5), "FC",
              "natural frequency ω/2π of the low-pass", log=True, bounds=(5.0, 2000.0),
              why="strain-gauge amplifiers filter at 10 Hz to a few kHz; above 1 kHz a "
                  "2 kHz recording cannot see it"),
        param("damping_ratio", "1", 0.7, (0.5, 1.2), (0.05, 10.0), "ZETA",
              "ζ of the low-pass (≥ 1: no overshoot, first-order-like)", bounds=(0.2, 3.0),
              why="a lightly damped load cell 0.2; Butterworth/Bessel filters 0.7–0.9; "
                  "cascaded RC stages overdamped"),
    ),
    # Richer forms: another order or resonance of the gauge: a mode in the F reading.
    richer=(("resonance", "F"),),
)
# fmt: on
