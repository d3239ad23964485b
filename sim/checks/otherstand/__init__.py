"""An independently written truth stand: STAND.md §2 and a second formulation of each §5 effect.

``diagnose-check --truth other`` draws its recordings from here. Written from STAND.md's
descriptions, never from the candidate models: it imports nothing of ``sim.effects``,
``sim.model``, ``sim.physics`` or ``sim.identify`` (an import-linter
contract), only the stand's geometry and nominal values (``sim.params``). Its own
integrator (``_kernel``), its own equations and ranges (``effects``), its own gauges and
noise (``gauges``), its own drive signals and campaigns (``campaign``).
"""

from sim.checks.otherstand.effects import OTHER_EFFECTS, OTHER_PAIRS, OTHER_TRIPLES, OtherEffect
from sim.checks.otherstand.stand import OtherRun, simulate

__all__ = ["OTHER_EFFECTS", "OTHER_PAIRS", "OTHER_TRIPLES", "OtherEffect", "OtherRun", "simulate"]
