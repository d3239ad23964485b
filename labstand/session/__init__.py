"""The acquisition session: devices by their interfaces in, a recorded run out.

``Session`` (pre-flight, prepare, run) on the loop of ``loop``, recording through
``record``, e-stop rules in ``safety``, the live status in ``display``; ``devices``
builds the drive and the gauge source of a backend.
"""

from labstand.session.session import (
    Outcome,
    Preflight,
    PreflightError,
    RunResult,
    Session,
    StopRequest,
)

__all__ = ["Outcome", "Preflight", "PreflightError", "RunResult", "Session", "StopRequest"]
