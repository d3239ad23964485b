"""The compiled model for a set of terms, written into one hash-named module (private).

``kernel.py`` holds the integrator, the runners and the built-in effects' terms. A model
runs a copy of it composed for its set: the layout's constants written in as literals
(``layout.constants``: which terms are in, where each state sits), the state's tuple
helpers written for the set's states, ``_added_force`` summing the forces of the
effects added with ``register``, and the hooks of added effects with terms of their own
(``EffectInfo.terms``: their states after the union's, their slots in c's block from
``layout.S_X``), written in as the built-in terms' are. A term that is out is pruned at
compile time, so the empty set is the baseline at the baseline's speed and, with the
arithmetic of every kept term unchanged, bit for bit what the union gives with every
effect off. Two sets
are composed: the empty one and the union of the built-in terms (with any added
effects) — compiled once each, like numba compiled the two kernels before.

The file's name is a hash of its whole text (the kernel's source, the layout, each added
effect's composed functions and its force's module source, numba's and Python's
versions): numba's cache does not notice an edit of a jitted function or a constant
imported from another module; a new name does.
Composed modules are written to ``cache_dir()`` and numba caches their machine code
beside them.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
import tempfile
import threading
from functools import cache
from pathlib import Path
from types import ModuleType

import numba

from sim.effects.info import EffectError, EffectInfo
from sim.physics import kernel_source, layout

__all__ = ["baseline", "cache_dir", "kernel_for", "union"]


def kernel_for(terms: tuple[str, ...], added: tuple[EffectInfo, ...] = ()) -> ModuleType:
    """The compiled model with these built-in terms (``layout.TERMS``) and added forces."""
    with _COMPOSING:  # traces run side by side: one thread writes and imports it
        return _composed(terms, tuple(sorted(added, key=lambda info: info.flag_column)))


def baseline() -> ModuleType:
    """The model without terms: the baseline of STAND.md §2."""
    return kernel_for(())


def union() -> ModuleType:
    """The model with every built-in term (an effect switched off adds exact zeros)."""
    return kernel_for(layout.TERMS)


_COMPOSING = threading.Lock()


def cache_dir() -> Path:
    """Where composed kernels are written: $LABSTAND_KERNEL_CACHE, else the user's cache."""
    given = os.environ.get("LABSTAND_KERNEL_CACHE")
    if given:
        return Path(given)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "labstand" / "kernels"


@cache  # one module per set and process: importing it twice would compile twice
def _composed(terms: tuple[str, ...], added: tuple[EffectInfo, ...]) -> ModuleType:
    source = source_for(terms, added)
    digest = hashlib.sha256(source.encode()).hexdigest()[:20]
    directory = cache_dir()
    path = directory / f"composed_{digest}.py"
    try:
        directory.mkdir(parents=True, exist_ok=True)
        if not path.exists():  # written whole, then renamed: a reader never sees half
            with tempfile.NamedTemporaryFile("w", dir=directory, suffix=".tmp", delete=False) as f:
                f.write(source)
            os.replace(f.name, path)
    except OSError as exc:
        raise EffectError(f"cannot write a composed kernel to {directory}: {exc}") from None
    name = f"sim.physics._composed_{digest}"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache finds a function's module by name
    spec.loader.exec_module(module)
    return module


def source_for(terms: tuple[str, ...], added: tuple[EffectInfo, ...] = ()) -> str:
    """The kernel's source composed for a set: its three marked blocks written for it."""
    text = kernel_source.text(terms, added)
    names = ", ".join(terms + tuple(info.name for info in added)) or "none (the baseline)"
    values = layout.constants(terms, added)
    head = [
        f"# <layout> composed for: {names}",
        f"# numba {numba.__version__}, Python {sys.version.split()[0]}",
        *(f"{key} = {value}" for key, value in sorted(values.items())),
        "",
    ]
    text = kernel_source.splice(text, "layout", "\n".join(head))
    text = kernel_source.splice(text, "state", kernel_source.state_block(terms, added))
    text = kernel_source.splice(text, "hooks", kernel_source.hooks_block(terms, added))
    text = kernel_source.splice_sites(text, terms, added)
    return kernel_source.splice(text, "added-force", _added_block(added))


def _added_block(added: tuple[EffectInfo, ...]) -> str:
    """``_added_force``: the sum of the added effects' forces that are on."""
    lines = ["# <added-force>"]
    forces = [info for info in added if info.weight_force is not None]
    for i, info in enumerate(forces):
        func = info.weight_force.py_func
        module = sys.modules[func.__module__]
        digest = hashlib.sha256(inspect.getsource(module).encode()).hexdigest()[:20]
        lines.append(f"from {func.__module__} import {func.__name__} as _added_{i}  # {digest}")
    lines += [
        "",
        "",
        '@njit(cache=True, error_model="numpy")',
        "def _added_force(c, y, t2):  # type: ignore[no-untyped-def]",
        '    """Force on the weight (N, up the incline) of the added effects that are on."""',
        "    force = 0.0",
    ]
    for i, info in enumerate(forces):
        values = "".join(f"c[{p.column}], " for p in info.params)
        lines += [
            f"    if c[{info.flag_column}] > 0.0:  # {info.name}",
            f"        force += _added_{i}(y[Y_U], y[Y_V], t2, ({values}))",
        ]
    lines += ["    return force", "", ""]
    return "\n".join(lines)
