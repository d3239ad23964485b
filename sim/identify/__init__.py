"""Sim-to-real gap diagnosis: where the gap lies, which effects explain it, how far it shrinks.

System identification on arrays (``Trace``): no file is read here; ``labstand`` reads the
recordings and hands their series over.

Exceptions::

    ValueError
     └── DiagnosisInputError   recordings that cannot be diagnosed (says what is missing)
"""

from sim.identify.pipeline import diagnose
from sim.identify.report import Diagnosis
from sim.identify.traces import DiagnosisInputError, Trace, make_trace

__all__ = ["Diagnosis", "DiagnosisInputError", "Trace", "diagnose", "make_trace"]
