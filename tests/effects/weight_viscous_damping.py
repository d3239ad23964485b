"""A tenth effect, written outside the kernel: viscous damping of the weight's motion.

An oil film on the guide or an eddy-current brake pulls on the weight against its
velocity, F = −b·v. This one file is all an added effect needs: its parameters (units,
ranges and why) and a compiled force on the weight. ``sim.effects.register(INFO)`` adds
it to the registry; models and the diagnosis then treat it like the nine of STAND.md §5.
"""

from __future__ import annotations

from numba import njit

from sim.effects.info import EffectInfo, param


@njit(cache=True, error_model="numpy")
def weight_force(u, v, tension, params):  # type: ignore[no-untyped-def]
    """−b·v: the force on the weight (N, up the incline) at velocity v (m/s)."""
    return -params[0] * v


# fmt: off
INFO = EffectInfo(
    "weight_viscous_damping", "physical",
    "a force −b·v on the weight against its velocity (oil film, eddy-current brake)",
    "force grows with the weight's speed in every test; rest and slow motion unaffected",
    "VD",  # its symbol; the registry gives the flag and parameter columns
    (
        param("damping_n_s_m", "N·s/m", 20.0, (5.0, 50.0), (0.0, 1000.0), "B",
              "b, damping coefficient of the weight's motion", log=True,
              bounds=(0.1, 300.0),
              why="a viscous film of 0.1–1 Pa·s over 100 cm² and 0.1 mm gives 10–100 N·s/m"),
    ),
    weight_force=weight_force,
)
# fmt: on
