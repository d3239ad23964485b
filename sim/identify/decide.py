"""The decision: whether a candidate's held-out gain is evidence of an effect or luck.

Every candidate is refitted on the training cycles and judged on the held-out ones, per
held-out block (a quarter second of a held-out cycle): the drop in mean squared error in
noise units (``block_improvements``). Under "no effect" — the candidate only moved
parameters that noise and the baseline's own parameter error let it move — held-out
gains scatter around zero, symmetric or worse (a refit that follows training noise
predicts held-out cycles worse). So the evidence is a one-sided Wilcoxon signed-rank test
of the blocks' gains against zero: its p-value is the chance of gains this consistent
from noise alone, without assuming how large they are where the effect shows and where
it does not (a t-test over blocks of very unequal gains had no power with three held-out
cycles, a sample-level test none of the calibration: neighbouring samples are not
independent). Choosing the best of m candidates is m tests, so
its p-value is multiplied by m (Bonferroni) before it is compared with ``ALPHA``; then the
false-alarm rate of a ``none`` campaign is at most ``ALPHA`` by construction, whatever
the noise level, rather than tuned by a closure threshold.

A gain must also exceed ``MIN_GAIN_OVER_NOISE`` of the reference's X (error in noise
units): the resolution of X itself (the noise it is measured in is estimated from the
rest before the motion, to about a tenth), below which no model difference is
meaningful. Judged per block as log-ratios, a candidate that is 1 % better on every
block is "consistent"; without this bar a second effect on top of the first was named
for closing 0.3 % of the gap (the demo's Maxwell branch, then string modes at p = 0.004).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import wilcoxon

from sim.identify.heldout import Outputs, block_errors, heldout_excess
from sim.identify.traces import Trace

#: Family-wise false-alarm rate of one decision (after the Bonferroni correction): a
#: ``none`` campaign is answered with an effect at most this often. 0.01 cost the small
#: check its dial gauge (closure 0.97, p = 0.0012 over 12 blocks, × 9 candidates).
ALPHA = 0.05
#: Least improvement of X (held-out error in noise units), as a share of the reference's
#: X, that counts at all: X's own resolution (1 noise unit is known to about 10 %).
MIN_GAIN_OVER_NOISE = 0.1

__all__ = ["ALPHA", "MIN_GAIN_OVER_NOISE", "Evidence", "compare"]


@dataclass(frozen=True)
class Evidence:
    """How a candidate compares with a reference model on the held-out cycles."""

    x_before: float  # reference's held-out error, noise units (1 = perfect)
    x_after: float  # candidate's
    p_value: float  # one-sided, single test: block gains centred on ≤ 0
    blocks: int

    @property
    def gain(self) -> float:
        """Drop of X, noise units."""
        return self.x_before - self.x_after

    def accepted(self, tests: int, alpha: float = ALPHA) -> bool:
        """Evidence of an effect when it was the best of ``tests`` candidates."""
        resolution = MIN_GAIN_OVER_NOISE * max(self.x_before, 1.0)
        return self.p_value * max(tests, 1) <= alpha and self.gain >= resolution


def p_value_of_gains(gains: np.ndarray) -> float:
    """One-sided p of "block gains are centred on ≤ 0" (Wilcoxon signed-rank)."""
    nonzero = gains[gains != 0.0]
    if nonzero.size < 2:
        return 1.0
    return float(wilcoxon(nonzero, alternative="greater").pvalue)


def compare(
    traces: Sequence[Trace], before: Sequence[Outputs], after: Sequence[Outputs]
) -> Evidence:
    """The held-out evidence that ``after`` predicts better than ``before``."""
    eb, ea = block_errors(traces, before, after)
    # Relative gains: log of the error ratio per block. Each block then counts by how
    # much the candidate improved on it, not by how large its error was: a trace whose
    # error neither model explains (a chaotic bounce, a form the candidate lacks) has
    # blocks of errors a hundred times the others', which drowned a candidate's
    # consistent threefold gain on every other trace (absolute gains: p = 0.18 after
    # the correction, relative: see docs/diagnosis.md, "The decision").
    gains = np.log(np.maximum(eb, 1e-300) / np.maximum(ea, 1e-300))
    return Evidence(
        x_before=heldout_excess(traces, before),
        x_after=heldout_excess(traces, after),
        p_value=p_value_of_gains(gains),
        blocks=int(gains.size),
    )
