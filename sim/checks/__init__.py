"""The checks: the diagnosis scored on campaigns whose truth is known, kept apart from it.

``check`` draws campaigns with a withheld effect, diagnoses them blind and scores the
answers; ``check_other`` turns the other stand's campaigns into traces; ``otherstand`` is
that other stand, a truth written apart from the candidate models. The checks use the
diagnosis (``sim.identify``) and the candidates (``sim.effects``); neither of those ever
imports the checks (import-linter contracts in ``pyproject.toml``). Nothing is imported
here, so ``import sim.checks.otherstand`` loads only the other stand.
"""
