"""Sim-to-real gap diagnosis: where the gap lies, which effect explains it, how far it shrinks.

Exceptions::

    ValueError
     └── DiagnosisInputError   recordings that cannot be diagnosed (says what is missing)
"""

from sim.identify.diagnose import Diagnosis, diagnose
from sim.identify.traces import DiagnosisInputError, Trace, make_trace

__all__ = ["Diagnosis", "DiagnosisInputError", "Trace", "diagnose", "make_trace"]
