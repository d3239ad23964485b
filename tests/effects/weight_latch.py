"""A tenth effect with a state and a switch, written outside the kernel: a weight latch.

A holding magnet at the top of the weight's guide. A limit switch turns its coil on when
the weight rises past the height h (its displacement from rest) and off again when it
falls below h − band (the switch's hysteresis). The magnet pulls the weight up the
incline with a force f that follows the coil's current, settling with the coil's time
constant τ = L/R toward F while on and toward 0 while off:

    ḟ = (F·on − f)/τ,    on: 0 → 1 when u ≥ h,  1 → 0 when u < h − band.

So while the weight is held high the fibre's tension falls by f/n (n the fibre's
projection on the guide), exponentially with τ after the switch.

This one file is all it needs: its parameters (``INFO``) and its compiled hooks, named
``lt_<hook>`` after its symbol LT, with the parameters ``sim.physics.kernel_source.HOOKS``
and ``STATE_HOOKS`` give them: ``lt_pack`` (its decay, for the substeps), ``lt_rest``,
``lt_rates`` and ``lt_start_state`` (its state f at rest, its rate, at a measured start),
``lt_weight`` (its force on the weight), ``lt_after_part`` (the switch, after every
integrated part of a step) and ``lt_start`` (the switch at a measured start); helpers
are named ``_lt_…``. ``sim.effects.register(INFO)`` composes them into the model.
"""

from __future__ import annotations

from numba import njit

from sim.effects.info import EffectInfo, param
from sim.physics.layout import I_U, I_V, Y_U

# Its names in the composed model, here for reading and linting only: ``register`` gives
# its columns and slot, its state follows the built-in ones, and ``compose`` writes each
# name into the composed model as a literal.
R_LT_ON = R_LT_FORCE = R_LT_TAU = R_LT_HEIGHT = R_LT_BAND = Y_LT_F = S_LT_COIL = -1


@njit(cache=True, error_model="numpy")
def lt_pack(c, osc, osc_exp, real):  # type: ignore[no-untyped-def]
    """The coil's decay 1/τ: the substeps resolve it."""
    if c[R_LT_ON] > 0.0:
        real = max(real, 1.0 / c[R_LT_TAU])
    return osc, osc_exp, real


@njit(cache=True, error_model="numpy")
def lt_rest(c):  # type: ignore[no-untyped-def]
    """At rest the weight is below the switch: the coil is off, no pull."""
    return (0.0,)


@njit(cache=True, error_model="numpy")
def lt_rates(c, y, sg, t1, t2, zd):  # type: ignore[no-untyped-def]
    """(ḟ,) = ((F·on − f)/τ,): the pull settles toward its switched value."""
    lt_rate = 0.0
    if c[R_LT_ON] > 0.0:
        lt_rate = (c[R_LT_FORCE] * c[S_LT_COIL] - y[Y_LT_F]) / c[R_LT_TAU]
    return (lt_rate,)


@njit(cache=True, error_model="numpy")
def lt_weight(c, y, v, t2, drive):  # type: ignore[no-untyped-def]
    """The magnet's pull on the weight, N, up the incline."""
    if c[R_LT_ON] > 0.0:
        drive += y[Y_LT_F]
    return drive


@njit(cache=True, error_model="numpy")
def lt_after_part(c, y, x, xd, h):  # type: ignore[no-untyped-def]
    """The limit switch after an integrated part of a step: on at h, off below h − band."""
    if c[R_LT_ON] > 0.0:
        if c[S_LT_COIL] == 0.0 and y[Y_U] >= c[R_LT_HEIGHT]:
            c[S_LT_COIL] = 1.0
        elif c[S_LT_COIL] > 0.0 and y[Y_U] < c[R_LT_HEIGHT] - c[R_LT_BAND]:
            c[S_LT_COIL] = 0.0


@njit(cache=True, error_model="numpy")
def _lt_switched(c, u, v):  # type: ignore[no-untyped-def]
    """The switch at a measured u, v: on above h, off below h − band; in the band on
    while the weight comes down (it passed h on its way up), off while it rises."""
    on = 0.0
    if u >= c[R_LT_HEIGHT] or (u >= c[R_LT_HEIGHT] - c[R_LT_BAND] and v < 0.0):
        on = 1.0
    return on


@njit(cache=True, error_model="numpy")
def lt_start(c, y, x, xd, m):  # type: ignore[no-untyped-def]
    """The switch at a segment's measured start."""
    if c[R_LT_ON] > 0.0:
        c[S_LT_COIL] = _lt_switched(c, m[I_U], m[I_V])


@njit(cache=True, error_model="numpy")
def lt_start_state(c, x, xd, u, v, force, taut, m):  # type: ignore[no-untyped-def]
    """(f,) at a measured start: settled at the switch's value (a chained run carries
    the previous segment's instead, ``carried``)."""
    f = 0.0
    if c[R_LT_ON] > 0.0:
        f = c[R_LT_FORCE] * _lt_switched(c, u, v)
    return (f,)


# fmt: off
INFO = EffectInfo(
    "weight_latch", "physical",
    "a holding magnet at the top of the guide, switched by a limit switch with hysteresis; "
    "its pull settles with the coil's time constant",
    "the force falls, exponentially, while the weight is held above the switch's height",
    "LT",  # its symbol: its hooks are lt_<hook>, its names R_LT_*, Y_LT_*, S_LT_*
    (
        param("force_n", "N", 8.0, (4.0, 15.0), (0.0, 200.0), "FORCE",
              "F, the magnet's settled pull on the weight with the coil on", log=True,
              bounds=(0.2, 40.0),
              why="holding magnets of 1–5 kg pull at a few mm's gap; beyond 40 N it would "
                  "lift a light weight off its fibre"),
        param("tau_s", "s", 0.08, (0.03, 0.2), (1e-3, 5.0), "TAU",
              "τ = L/R, the coil's time constant", log=True, bounds=(0.005, 1.0),
              why="a holding magnet's coil: tens of mH over tens of Ω, 5 ms to 1 s"),
        param("height_m", "m", 0.02, (0.02, 0.02), (1e-4, 0.5), "HEIGHT",
              "h, the weight's displacement from rest at which the switch turns the coil on",
              fit=False, why="where the limit switch is mounted: measured on the stand"),
        param("band_m", "m", 0.002, (0.002, 0.002), (0.0, 0.05), "BAND",
              "the limit switch's hysteresis: off again below h − band", fit=False,
              why="the switch's data sheet"),
    ),
    carried=True,  # a segment run after the first starts from the previous one's pull
    terms=__name__,  # this module: its hooks are composed into the model
    states=("F",),  # f, N: Y_LT_F
    slots=("COIL",),  # the switch, 1.0 while the coil is on: S_LT_COIL
)
# fmt: on
