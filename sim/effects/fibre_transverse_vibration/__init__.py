"""The free spans' string modes, loaded by gravity's transverse component.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

from sim.effects.info import EffectInfo, param

# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "fibre_transverse_vibration", "physical",
    "first string mode of each free span (f = 1/2ℓ·√(T/μ)), loaded by gravity's "
    "transverse component; its geometric stretch π²a²/4ℓ lengthens the fibre path",
    "force ripple (at 2f, and f with sag) after snatches; displacement nearly unaffected",
    "TV",
    (
        param("damping_ratio", "1", 0.02, (0.005, 0.1), (1.0e-4, 1.0), "ZETA",
              "modal damping ratio of the string modes (at rest tension)", log=True,
              bounds=(1.0e-3, 0.3),
              why="carbon fibre's internal damping is 0.1–1 %; air drag on a slack filament "
                  "bundle adds up to tens of per cent"),
        param("load_scale", "1", 1.0, (0.5, 2.0), (0.0, 10.0), "LOAD",
              "multiplier on gravity's transverse load on the spans (0: never excited)",
              bounds=(0.1, 5.0),
              why="drafts, guide misalignment and pulley run-out excite the spans several "
                  "times more than gravity alone; below 0.1 the modes stay in the noise"),
        param("drive_span_tilt_deg", "deg", 5.0, (0.0, 15.0), (0.0, 90.0), "TILT",
              "tilt of the (vertical) drive span from the vertical", fit=False),
    ),
    carried=True,
    # Richer forms: more modes, other damping: a mode of the tension.
    richer=(("resonance", "u+F"),),
)
# fmt: on
