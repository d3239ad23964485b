"""What a check can be asked for: plain names, so a CLI's parser needs no numba to list them."""

from __future__ import annotations

#: Where a check's truth comes from: the candidates' own code, the other stand, or the
#: other stand with effects outside the catalogue (``sim.checks.otherstand.outside``).
TRUTHS = ("same", "other", "outside")
MASSES_KG = (3.096, 8.131)
#: A ``none`` campaign whose recorder adds artefacts (``Realism.with_artefacts``).
ARTEFACTS = "artefacts"
#: The recording sets a check can draw its campaigns with (``check.recording_set``): the
#: other stand's (the validation campaigns' four drive signals are ``moderate``), and the
#: paper-like quick, medium and slow recordings the first checks used.
RECORDING_SETS = ("moderate", "gentle", "brisk", "paper")
