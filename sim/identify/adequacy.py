"""Could the fitted model itself leave this held-out error? A test for a gross misfit.

The remainder's test (``remainder``) asks whether what remains is *systematic*: whether
the training cycles predict the held-out ones. A model stuck in a wrong basin, or a
misfit that is irregular from cycle to cycle, can leave a held-out error of a hundred
times the noise that no signature term predicts; that test alone would then say
"baseline adequate", and a user reads "the model is right".

This test asks the other question: is the held-out error one that the fitted model
leaves on recordings it makes itself? Its replicates (``replicates.replicate_traces``:
the model's own outputs on each recording's drive, plus each gauge's noise at its rest
level, the same lost samples and held-out split) are restarted from their own noisy
measured states, so the restart error and a slack fibre's chaotic bounce are in them as
they are in the recordings. The observed excess is gross when it lies above the
replicates' one-sided prediction bound at ``GROSS_ALPHA`` (Student t on the replicates'
log excess), widened by how well the noise unit is known (the rest spread the excess
counts in, ``balance.noise_resolution``), since the replicates use that unit as exact.
A right model is called a gross misfit at most about ``GROSS_ALPHA`` of the time, beside
the remainder test's own rate, where the replicates carry what the recordings do; with
effects named they did not (a right branch on ``make demo`` left 1.5× its replicates), so
there ``remainder`` reports the comparison without letting it decide.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from sim.identify.balance import noise_resolution
from sim.identify.fitting import Candidate, simulate_values
from sim.identify.heldout import Outputs, heldout_excess
from sim.identify.replicates import replicate_traces
from sim.identify.traces import Trace
from sim.params import StandParams

__all__ = ["GROSS_ALPHA", "NOISELESS", "OWN_REPLICATES", "OwnExcess", "own_excess"]

#: Recordings the fitted model makes of itself (each one simulation per recording).
OWN_REPLICATES = 8
#: How often a right model is called a gross misfit, at most (about: the bound assumes
#: the replicates' log excess is normal).
GROSS_ALPHA = 1e-3
#: Replicates whose held-out excess falls below this carry no noise in some channel (a
#: recording without noise, or read in steps too fine to see): no bound is drawn.
NOISELESS = 1e-6


@dataclass(frozen=True)
class OwnExcess:
    """The held-out excess observed, and what the fitted model leaves on its own replicates."""

    observed: float
    replicates: tuple[float, ...]
    #: The largest excess a right model leaves, at ``GROSS_ALPHA``.
    bound: float

    @property
    def gross(self) -> bool:
        """The observed excess is beyond anything the fitted model itself leaves."""
        return self.observed > self.bound

    def to_dict(self) -> dict[str, object]:
        """JSON: observed, the replicates' median and range, the bound (null: none), gross."""
        reps = np.asarray(self.replicates)
        return {
            "observed": self.observed,
            "replicates_median": float(np.median(reps)),
            "replicates_range": [float(reps.min()), float(reps.max())],
            "bound": self.bound if math.isfinite(self.bound) else None,
            "alpha": GROSS_ALPHA,
            "gross": self.gross,
        }


def prediction_bound(excesses: Sequence[float], resolution: float) -> float:
    """One-sided upper ``GROSS_ALPHA`` bound of one more excess like these (log-normal).

    ``resolution``: the noise unit's relative standard error, added in quadrature.
    Infinite (no bound) where a replicate fell below ``NOISELESS``.
    """
    if not all(math.isfinite(x) and x >= NOISELESS for x in excesses):
        return math.inf
    logs = np.log(np.asarray(excesses, float))
    n = logs.size
    spread = float(np.std(logs, ddof=1)) if n > 1 else 0.0
    t = float(stats.t.ppf(1.0 - GROSS_ALPHA, max(n - 1, 1)))
    return math.exp(float(np.mean(logs)) + t * math.hypot(spread * math.sqrt(1 + 1 / n),
                                                          resolution))  # fmt: skip


def own_excess(
    candidate: Candidate,
    values: dict[str, float],
    traces: Sequence[Trace],
    nominal: StandParams,
    observed: float,
    replicates: int = OWN_REPLICATES,
    seed: int = 1,
) -> tuple[OwnExcess, int]:
    """The fitted model's held-out excess on ``replicates`` recordings of its own.

    Returns the comparison and the simulations spent.
    """
    rng = np.random.default_rng(seed)
    xs = []
    for drawn in replicate_traces(candidate, values, traces, nominal, rng, replicates):
        outputs = []
        for tr in drawn:
            u, f = simulate_values(candidate, [values], tr, nominal)
            outputs.append(Outputs(u[0], f[0]))
        xs.append(heldout_excess(drawn, outputs))
    bound = prediction_bound(xs, noise_resolution(traces))
    return OwnExcess(observed, tuple(xs), bound), len(traces) * (1 + replicates)
