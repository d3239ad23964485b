"""Stick-slip of the weight on its guide: LuGre friction with a Stribeck rise.

Terms: ``sim.physics.kernel`` (why there: docs/architecture.md); equations: docs/effects.md.
"""

from __future__ import annotations

from sim.effects.info import EffectInfo, param

# The same declarative shape in every effect module (what it means: sim/effects/info.py).
# fmt: off
INFO = EffectInfo(
    "stick_slip_friction", "physical",
    "LuGre friction: bristle state z, ż = v − σ₀|v|z/g(v), F = σ₀z + σ₁ż with "
    "g(v) = table friction·(1 + r·exp(−|v/v_s|^δ)); needs the stand's friction table",
    "residual at velocity reversals and at low speed, visible in slow tests",
    "SS",
    (
        param("static_ratio", "1", 0.4, (0.1, 0.8), (0.0, 5.0), "RATIO",
              "r: static friction exceeds kinetic by this fraction", bounds=(0.0, 3.0),
              why="static/kinetic friction ratios of steel on lubricated or dry guides lie "
                  "between 1 and about 4"),
        param("stribeck_speed_m_s", "m/s", 3.0e-3, (1.0e-3, 1.0e-2), (1.0e-5, 1.0), "VS",
              "v_s: speed over which friction falls to kinetic", log=True,
              bounds=(1.0e-4, 0.1),
              why="lubricated line contacts show Stribeck speeds from 0.1 mm/s to 0.1 m/s"),
        param("stribeck_exponent", "1", 2.0, (2.0, 2.0), (0.1, 10.0), "EXP",
              "δ: how the friction falls from static to kinetic, exp(−|v/v_s|^δ)",
              drawn=False, bounds=(0.5, 3.0),
              why="measured Stribeck curves fall exponentially (δ ≈ 0.5–1) to like a "
                  "Gaussian (δ = 2) or steeper, with the lubricant and the surfaces"),
        param("bristle_stiffness_n_m", "N/m", 1.0e5, (3.0e4, 3.0e5), (1.0e3, 1.0e7),
              "SIGMA", "σ₀, presliding stiffness (σ₁ = 2√(σ₀m))", log=True,
              drawn=False, form=True, bounds=(3.0e4, 1.0e6),
              why="the contact's stiffness before it slides: the weight's 1.7–4.5 N of "
                  "kinetic friction over a presliding displacement of 2–150 µm (steel on "
                  "greased steel: micrometres to a tenth of a millimetre); a stick band "
                  "that holds the weight still (Karnopp) is its stiff limit"),
    ),
    carried=True,
    # Richer forms: another friction curve: speed shapes on the weight.
    richer=(("velocity", "u+F"),),
)
# fmt: on
