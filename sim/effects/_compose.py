"""Kernels composed with the effects added outside ``sim.effects.kernel`` (private to sim).

An effect registered with ``sim.effects.registry.register`` brings a compiled force on the
weight. A model with such an effect on runs a copy of the kernel whose ``_added_force``
(between the ``<added-force>`` markers) calls those forces, written to a source file of
its own and imported from there, so that numba compiles it at full speed and caches it
like the kernel itself. The file's name is a hash of everything its machine code
depends on (the kernel's source, each added effect's module source and columns, numba's
and Python's versions): numba's cache does not notice an edit of a jitted function
imported from another module, a new name does. Models without added effects run the
kernel itself.
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

from sim.effects import kernel as ek
from sim.effects.info import EffectError, EffectInfo

__all__ = ["kernel_for"]

_START = "# <added-force>"
_END = "# </added-force>"


def kernel_for(added: tuple[EffectInfo, ...]) -> ModuleType:
    """The kernel module for rows with these added effects on (the kernel if none)."""
    if not added:
        return ek
    with _COMPOSING:  # traces run side by side: one thread writes and imports it
        return _composed(tuple(sorted(added, key=lambda info: info.flag_column)))


_COMPOSING = threading.Lock()


def cache_dir() -> Path:
    """Where composed kernels are written: $LABSTAND_KERNEL_CACHE, else the user's cache."""
    given = os.environ.get("LABSTAND_KERNEL_CACHE")
    if given:
        return Path(given)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "labstand" / "kernels"


@cache  # one module per effect set and process: importing it twice would compile twice
def _composed(added: tuple[EffectInfo, ...]) -> ModuleType:
    source = _source(added)
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
    name = f"sim.effects._composed_{digest}"
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache finds a function's module by name
    spec.loader.exec_module(module)
    return module


def _source(added: tuple[EffectInfo, ...]) -> str:
    """The kernel's source with ``_added_force`` summing the added effects' forces."""
    text = Path(inspect.getfile(ek)).read_text(encoding="utf-8")
    head, rest = text.split(_START, 1)
    _, tail = rest.split(_END, 1)
    names = ", ".join(info.name for info in added)
    lines = [
        f"{_START} composed for: {names}",
        f"# numba {numba.__version__}, Python {sys.version.split()[0]}",
    ]
    for i, info in enumerate(added):
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
    for i, info in enumerate(added):
        values = "".join(f"c[{p.column}], " for p in info.params)
        lines += [
            f"    if c[{info.flag_column}] > 0.0:  # {info.name}",
            f"        force += _added_{i}(y[Y_U], y[Y_V], t2, ({values}))",
        ]
    lines += ["    return force", "", "", ""]
    return head + "\n".join(lines) + _END + tail
