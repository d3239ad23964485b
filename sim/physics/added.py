"""What an effect added from outside must bring for the model to compose it (plain Python).

``sim.effects.register`` calls ``check`` before it registers an effect: a compiled force
on the weight (``EffectInfo.weight_force``), terms of its own (``EffectInfo.terms``: the
hooks ``<symbol>_<hook>`` of ``kernel_source.HOOKS`` and ``STATE_HOOKS`` in its one file,
composed in as the built-in terms are), or both; or, a gauge effect, what its gauge
records (``EffectInfo.record``, with its inverse ``invert``: ``sim.physics.gauges``),
tried once on a short run here. A mistake in its file is a one-line
``EffectError`` here, not a compile error inside numba at its first run.
"""

from __future__ import annotations

import ast

import numpy as np

from sim.effects.info import EffectError, EffectInfo
from sim.physics import kernel_source, layout

__all__ = ["check", "slot_range"]

#: Names an added effect's symbol must not take: the built-in ones, and the layout's
#: prefixes (``R_X_ON`` and ``S_X`` would read as an effect ``X``'s).
_RESERVED = {info.symbol for info in layout.PLACED} | {"X"}


def check(info: EffectInfo, others: tuple[EffectInfo, ...]) -> None:
    """EffectError (one line) unless the model can compose ``info`` beside ``others``."""
    if info.kind == "measurement" or info.record is not None or info.invert is not None:
        _check_gauge(info)
        return
    if not info.added:
        raise EffectError(
            f"{info.name}: an added effect needs a compiled (njit) weight_force or terms"
        )
    if info.weight_force is not None and not hasattr(info.weight_force, "py_func"):
        raise EffectError(f"{info.name}: its weight_force must be compiled (njit)")
    if info.terms is not None:  # its hooks' and names' prefix: its own
        symbol = info.symbol
        if not (symbol.isidentifier() and symbol.isupper()):
            raise EffectError(f"{info.name}: its symbol {symbol!r} must be an upper-case name")
        if symbol in _RESERVED | {other.symbol for other in others if other.terms}:
            raise EffectError(f"{info.name}: the symbol {symbol} is taken; choose another")
    for names, what in ((info.states, "state"), (info.slots, "slot")):
        bad = [n for n in names if not (n.isidentifier() and n.isupper())] or [
            n for n in names if names.count(n) > 1
        ]
        if bad:
            raise EffectError(f"{info.name}: {what} name {bad[0]!r} (upper-case, each once)")
    if info.terms is None:
        if info.states or info.slots:
            raise EffectError(f"{info.name}: states and slots need terms (its hooks' module)")
        return
    try:
        _check_terms(info)
    except (ImportError, OSError, SyntaxError, ValueError) as exc:
        raise EffectError(f"{info.name}: {exc}") from None


def slot_range(infos: tuple[EffectInfo, ...]) -> int:
    """The first free slot after these effects' (``layout.S_X`` if none has one)."""
    ends = [info.slot_index + len(info.slots) for info in infos if info.slots]
    return max(ends, default=layout.S_X)


def _check_terms(info: EffectInfo) -> None:
    """Its file's hooks: known names, compiled, the hooks' parameters, spliceable bodies."""
    path = kernel_source.added_file(info)
    prefix = f"{info.symbol.lower()}_"
    hooks = {h: args for h, (args, *_) in kernel_source.HOOKS.items()}
    hooks.update({h: args for h, (args, *_) in kernel_source.STATE_HOOKS.items()})
    defined = set()
    for node in kernel_source.composed_functions(path, info.symbol):
        if not any(_is_njit(d) for d in node.decorator_list):
            raise ValueError(f"{path.name}: {node.name} must be compiled, @njit(...)")
        if node.name.startswith("_"):
            continue  # a helper
        hook = node.name.removeprefix(prefix)
        if hook not in hooks:
            raise ValueError(
                f"{path.name}: {node.name} is no hook (hooks: {', '.join(hooks)}; "
                f"helpers are named _{prefix}…)"
            )
        if tuple(a.arg for a in node.args.args) != hooks[hook]:
            raise ValueError(f"{path.name}: {node.name} must take ({', '.join(hooks[hook])})")
        defined.add(hook)
    if info.states and "rates" not in defined:
        raise ValueError(f"{path.name}: its states need {prefix}rates")
    if not defined:
        raise ValueError(f"{path.name}: no hook {prefix}<hook> in it")
    # Compose its text once (no compile): a spliced hook's body must fit its site.
    kernel_source.splice_sites(kernel_source.text(layout.TERMS, (info,)), layout.TERMS, (info,))


def _is_njit(decorator: ast.expr) -> bool:
    """``@njit`` or ``@njit(...)``: the name the composed module imports from numba."""
    target = decorator.func if isinstance(decorator, ast.Call) else decorator
    return isinstance(target, ast.Name) and target.id == "njit"


def _check_gauge(info: EffectInfo) -> None:
    """A gauge effect: a record (and maybe an inverse) alone, which run and invert."""
    if info.kind != "measurement":
        raise EffectError(f"{info.name}: a record (a gauge transform) needs kind 'measurement'")
    if info.composed or info.states or info.slots or info.start_state or info.true_channels:
        raise EffectError(
            f"{info.name}: a gauge effect brings record (and invert) only, no physics"
        )
    if not callable(info.record):
        raise EffectError(f"{info.name}: a gauge effect needs record(values, t_s, u, force)")
    if info.invert is not None and not callable(info.invert):
        raise EffectError(f"{info.name}: its invert must be a function")
    # A short run at its defaults: a moving weight, a force with a swing.
    values = np.array([p.default for p in info.params], dtype=np.float64)
    t = np.arange(200) / 2000.0
    u = 0.01 * np.sin(2 * np.pi * 3.0 * t)
    force = 60.0 + 20.0 * np.sin(2 * np.pi * 5.0 * t)
    v = np.gradient(u, t)
    try:
        rec_u, rec_f = _arrays(info.record(values, t, u.copy(), force.copy()), 2, t.size, "record")
        if info.invert is None:
            return
        back_u, _, back_f = _arrays(info.invert(values, t, rec_u, v, rec_f), 3, t.size, "invert")
    except Exception as exc:  # its own code: any mistake, in one line
        first = (str(exc).strip().splitlines() or [""])[0]
        raise EffectError(f"{info.name}: its gauge fails on a trial run: {first}") from None
    for name, back, true in (("u", back_u, u), ("force", back_f, force)):
        if not np.allclose(back, true, rtol=1e-6, atol=1e-9 * np.abs(true).max()):
            raise EffectError(f"{info.name}: its invert does not give back the true {name}")


def _arrays(out: object, count: int, n: int, hook: str) -> tuple[np.ndarray, ...]:
    """``count`` finite float arrays of n samples, or ValueError."""
    if not isinstance(out, tuple) or len(out) != count:
        raise ValueError(f"{hook} must return a tuple of {count} arrays")
    arrays = tuple(np.asarray(a, dtype=np.float64) for a in out)
    if any(a.shape != (n,) or not np.all(np.isfinite(a)) for a in arrays):
        raise ValueError(f"{hook} must return finite arrays of its input's shape")
    return arrays
