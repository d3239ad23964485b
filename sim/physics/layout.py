"""Where everything sits: the parameter row, the constants array c, the state, the starts.

Computed from the registry's order (``sim.effects.builtin.BUILT_IN``), not numbered by
hand: the row holds the baseline's eight parameters (``sim.model``'s order), the stand's
geometry, then per effect its flag (1.0 on) and its parameters as it declares them, then
the block of effects added with ``register``. The constants array c of one run holds the
row, then the derived constants (``D_*``), the discrete state (``S_*``), the exponential
step's cache (``E_*``), the added effects' slots (from ``S_X``) and the friction table
(``C_TABLE``). The names are the kernel's (``sim/physics/kernel.py``): an effect's flag
``R_<symbol>_ON``, its parameters ``R_<symbol>_<parameter symbol>``, both symbols
declared in its module; an added effect's slots ``S_<symbol>_<slot>``.

The state y is a tuple of the composed set's states in one order (``STATES``): the
baseline's u, v, then each term's own, then the added effects' (``every_state``:
``Y_<symbol>_<state>``). Plain Python: reading it loads no numba.
"""

from __future__ import annotations

from dataclasses import replace

from sim.effects.builtin import BUILT_IN
from sim.effects.info import EffectInfo

# The baseline's parameters (``sim.physics.runs.param_vector``), then the stand geometry.
(P_MASS, P_PROJ, P_STIFF, P_DAMP, P_FRICTION_N, P_GRAVITY_N, P_PRELOAD, P_VREG) = range(8)
(R_DRIVE_SPAN, R_FREE_SPAN, R_FIBRE_LEN, R_LIN_DENSITY, R_SIN_BETA, R_G_PERP_WEIGHT_SPAN,
 R_GRAVITY, R_SIN_HALF_WRAP, R_RADIUS) = range(8, 17)  # fmt: skip
STAND_COLUMNS = 17


def place(infos: tuple[EffectInfo, ...], first: int) -> tuple[tuple[EffectInfo, ...], int]:
    """The effects with their columns from ``first`` on, in order; and the next free column."""
    placed = []
    column = first
    for info in infos:
        params = tuple(replace(p, column=column + 1 + i) for i, p in enumerate(info.params))
        placed.append(replace(info, flag_column=column, params=params))
        column += 1 + len(params)
    return tuple(placed), column


#: The built-in effects with their row columns (what ``EFFECTS`` holds for them).
PLACED, R_X_ON = place(BUILT_IN, STAND_COLUMNS)


def _columns(effect: str, *params: str) -> tuple[int, ...]:
    """The flag column of the effect with this symbol, then its parameters' by symbol."""
    info = next(i for i in PLACED if i.symbol == effect)
    by_symbol = {p.symbol: p.column for p in info.params}
    return (info.flag_column, *(by_symbol[p] for p in params))


R_VE_ON, R_VE_K, R_VE_TAU = _columns("VE", "K", "TAU")
R_TV_ON, R_TV_ZETA, R_TV_LOAD, R_TV_TILT = _columns("TV", "ZETA", "LOAD", "TILT")
R_PJ_ON, R_PJ_STEP, R_PJ_DEPTH, R_PJ_ONSET, R_PJ_DWELL, R_PJ_SEATS = _columns(
    "PJ", "STEP", "DEPTH", "ONSET", "DWELL", "SEATS"
)
R_PI_ON, R_PI_J, R_PI_TORQUE, R_PI_LOAD, R_PI_PRESLIDE = _columns(
    "PI", "J", "TORQUE", "LOAD", "PRESLIDE"
)
R_SS_ON, R_SS_RATIO, R_SS_VS, R_SS_EXP, R_SS_SIGMA = _columns("SS", "RATIO", "VS", "EXP", "SIGMA")
R_SL_ON, R_SL_MU = _columns("SL", "MU")
R_DG_ON, R_DG_GAIN, R_DG_OFFSET = _columns("DG", "GAIN", "OFFSET")
R_CS_ON, R_CS_FORCE, R_CS_DISP = _columns("CS", "FORCE", "DISP")
R_FG_ON, R_FG_FC, R_FG_ZETA = _columns("FG", "FC", "ZETA")
# Effects added with ``register``: R_X_ON is 1.0 when any is on; each has a flag and its
# parameters in the N_X columns from R_X.
R_X = R_X_ON + 1
N_X = 8
N_ROW = R_X + N_X
# Derived constants, then the discrete state, then the exponential step's cache (on in
# this interval; the rim's decay rate at rest; the oscillation bound with them exact;
# the rim's weights: rate, step, then six weights from E_W), then the friction table.
(D_NSEG, D_T0, D_K1, D_C1, D_K2, D_C2, D_D10, D_D20, D_MP, D_FB0, D_FBL, D_SIGP, D_KB1,
 D_KB2, D_RELAX, D_W1, D_W2, D_F1, D_F2, D_CM1, D_CM2, D_AR1SQ, D_AR2SQ, D_ST1, D_ST2,
 D_AR1, D_AR2, D_SS_ON, D_SIG0, D_SIG1, D_SL, D_OSC, D_REAL, D_DYN, D_ZONES,
 ) = range(N_ROW, N_ROW + 35)  # fmt: skip
(S_TAUT1, S_TAUT2, S_ZONE, S_LOFF, S_LBASE, S_DEPTH, S_PZ, S_PS0, S_SLACKT,
 ) = range(D_ZONES + 1, D_ZONES + 10)  # fmt: skip
E_ON, E_RIM, E_OSC, E_RATE, E_H, E_W = range(S_SLACKT + 1, S_SLACKT + 7)
# The pulley seat follows the recorded slack episodes, not the model's: 1.0 while a run
# is given them.
S_RECSEAT = E_W + 6
# Effects added with ``register``: their discrete states and derived constants (``slots``)
# in the N_SX values from S_X.
S_X = S_RECSEAT + 1
N_SX = 8
C_TABLE = S_X + N_SX  # c[C_TABLE] = knots n, then the n knots, then coef (4, n − 1) by rows

# A segment's measured start (``kernel.measured_state``): columns of init[b, s]. I_FRATE:
# the recorded force's rate (the force gauge filter's state, ``sim.effects.measure``).
(I_U, I_V, I_F, I_HP, I_LOFF, I_LBASE, I_DEPTH, I_SLACKT, I_FRATE) = range(9)
N_INIT = 9

#: The states in their order, each with the term that owns it ("" the baseline's).
STATES = (
    ("U", ""), ("V", ""), ("S", "PI"), ("SD", "PI"), ("Q1", "VE"), ("Q2", "VE"),
    ("A1", "TV"), ("AD1", "TV"), ("A2", "TV"), ("AD2", "TV"), ("Z", "SS"),
)  # fmt: skip
#: The states that carry over from segment to segment (invisible to the gauges).
CARRIED = ("A1", "AD1", "A2", "AD2", "Z")
#: The built-in effects with terms in the kernel (the others act on the outputs).
TERMS = tuple(i.symbol for i in PLACED if i.kind == "physical")

# The union's states (every built-in term): what the kernel's source reads as itself.
(Y_U, Y_V, Y_S, Y_SD, Y_Q1, Y_Q2, Y_A1, Y_AD1, Y_A2, Y_AD2, Y_Z) = range(11)
NY = 11


def every_state(added: tuple[EffectInfo, ...] = ()) -> tuple[tuple[str, str], ...]:
    """``STATES``, then the added effects' own (``<symbol>_<state>``), each with its owner."""
    return STATES + tuple((f"{i.symbol}_{s}", i.symbol) for i in added for s in i.states)


def carried(added: tuple[EffectInfo, ...] = ()) -> tuple[str, ...]:
    """``CARRIED``, then the states of the added effects that carry theirs."""
    return CARRIED + tuple(f"{i.symbol}_{s}" for i in added if i.carried for s in i.states)


def state_names(terms: tuple[str, ...], added: tuple[EffectInfo, ...] = ()) -> tuple[str, ...]:
    """The states of a composed set of built-in terms and added effects, in order."""
    symbols = set(terms) | {info.symbol for info in added}
    return tuple(name for name, owner in every_state(added) if not owner or owner in symbols)


def added_names(info: EffectInfo) -> dict[str, int]:
    """An added effect's names as its hooks read them: columns, slots (not its states)."""
    names = {f"R_{info.symbol}_ON": info.flag_column}
    names.update({f"R_{info.symbol}_{p.symbol}": p.column for p in info.params})
    names.update({f"S_{info.symbol}_{s}": info.slot_index + i for i, s in enumerate(info.slots)})
    return names


def constants(terms: tuple[str, ...], added: tuple[EffectInfo, ...] = ()) -> dict[str, int]:
    """Every layout constant of a composed kernel with these built-in terms, added effects.

    ``Y_*`` index the set's states (-1: a state the set lacks, only read in code its
    ``ON_*`` switch prunes); ``ON_<symbol>`` says whether a term is composed in, ``ON_X``
    whether added effects' forces (``weight_force``) are. An added effect's own names
    (``added_names``, ``Y_<symbol>_<state>``) come with it.
    """
    names = state_names(terms, added)
    values = {k: v for k, v in globals().items() if k.isupper() and type(v) is int}
    for name, _ in every_state(added):
        values[f"Y_{name}"] = names.index(name) if name in names else -1
    values["NY"] = len(names)
    for symbol in TERMS:
        values[f"ON_{symbol}"] = int(symbol in terms)
    for info in added:
        if info.terms:  # a force alone gets its columns in ``_added_force``'s call
            values.update(added_names(info))
    values["ON_X"] = int(any(info.weight_force is not None for info in added))
    # The most fibre segments the set has: the pulley's rim splits the fibre in two.
    values["SEGMENTS"] = 2 if "PI" in terms else 1
    values["ON_ANY"] = int(bool(terms) or bool(added))
    return values
