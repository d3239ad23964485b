"""Start points for the Maxwell-branch refit with the baseline's absorbed share given back.

Without a branch in its model, the baseline fit takes the branch's share of the fibre's
dynamic stiffness and damping into k and c. At the frequencies where the fibre and the
weight ring, ω₀ = n·√(k/m), a standard linear solid's branch (k₂ in series with a
dashpot k₂τ) adds the storage stiffness k₂(ω₀τ)²/(1 + (ω₀τ)²) and the loss damping
k₂τ/(1 + (ω₀τ)²). The refit's start grid holds the baseline at its fit, so every branch
it tries comes on top of what the baseline already absorbed. On a heavy same-form
campaign (k₂ 3.0e4 N/m, τ 0.071 s) the baseline ended at ×2.0 stiffness (its bound) and
×3.5 damping; with the true branch on top the training cost was 25 times the baseline's,
so the grid chose a weak, slow branch (τ 0.49 s, closure 0.32, ``none``), while a refit
from the true branch found k ×1.45 and closed 0.75 of the gap. With the absorbed share
given back, the points near the truth cost the baseline's or less. Each grid point gets
that twin; the local fit and the held-out test still decide.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from sim.identify.fitting import EFFECT_GRID_LEVELS, Candidate, grid_axis
from sim.identify.traces import Trace
from sim.params import StandParams

EFFECT = "fibre_viscoelastic"
_K2 = f"{EFFECT}.branch_stiffness_n_m"
_TAU = f"{EFFECT}.relaxation_time_s"


def absorbed_share(
    k2_n_m: float, tau_s: float, stiffness_n_m: float, mass_kg: float, projection: float
) -> tuple[float, float]:
    """The branch's storage stiffness (N/m) and loss damping (N·s/m) at the ring mode."""
    omega = projection * np.sqrt(stiffness_n_m / mass_kg)
    wt2 = (omega * tau_s) ** 2
    return k2_n_m * wt2 / (1.0 + wt2), k2_n_m * tau_s / (1.0 + wt2)


def branch_starts(
    traces: Sequence[Trace], nominal: StandParams, values: dict[str, float]
) -> list[dict[str, float]]:
    """The branch's grid points, each with the baseline's k and c less the branch's share.

    ``values``: the fit the refit starts from (its stiffness and damping scales). Points
    whose share would take k or c below their fitting bounds are left out.
    """
    cand = Candidate.build(EFFECT)
    params = {p.name: p for p in cand.params}
    own = [params[_K2], params[_TAU]]
    axes = [grid_axis(p, EFFECT_GRID_LEVELS[len(own)]) for p in own]
    k_fit = values["stiffness_scale"] * nominal.stiffness_n_m
    c_fit = values["damping_scale"] * nominal.damping_n_s_m
    mass = float(np.mean([tr.mass_kg for tr in traces]))
    k_low, c_low = params["stiffness_scale"].low, params["damping_scale"].low
    starts = []
    for z_k2, z_tau in itertools.product(*axes):
        k2, tau = own[0].to_natural(z_k2), own[1].to_natural(z_tau)
        stiff, damp = absorbed_share(k2, tau, k_fit, mass, nominal.projection)
        k_scale = (k_fit - stiff) / nominal.stiffness_n_m
        c_scale = (c_fit - damp) / nominal.damping_n_s_m
        if k_scale < k_low or c_scale < c_low:
            continue
        starts.append({"stiffness_scale": k_scale, "damping_scale": c_scale, _K2: k2, _TAU: tau})
    return starts
