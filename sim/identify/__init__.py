"""Sim-to-real gap diagnosis: where the gap lies, which effects explain it, how far it shrinks.

System identification on arrays (``Trace``): no file is read here; ``labstand`` reads the
recordings and hands their series over.

Exceptions::

    ValueError
     └── DiagnosisInputError   recordings that cannot be diagnosed (says what is missing)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Lazy re-exports (PEP 562): importing one module of the package (``sim.identify.errors``,
# say) must not load the heavy ones (numba, scipy, pandas, h5py, ...) through it.
_EXPORTS = {
    "diagnose": "sim.identify.diagnose",
    "Diagnosis": "sim.identify.report",
    "DiagnosisInputError": "sim.identify.traces",
    "Trace": "sim.identify.traces",
    "make_trace": "sim.identify.traces",
}

if TYPE_CHECKING:
    from sim.identify.diagnose import diagnose
    from sim.identify.report import Diagnosis
    from sim.identify.traces import DiagnosisInputError, Trace, make_trace


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'sim.identify' has no attribute {name!r}")
    if module == f"{__name__}.{name}":  # a submodule
        return importlib.import_module(module)
    return getattr(importlib.import_module(module), name)


__all__ = ["Diagnosis", "DiagnosisInputError", "Trace", "diagnose", "make_trace"]
