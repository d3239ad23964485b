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
independent). Judging m candidates is m tests: they are judged as one family
(``judge``: a candidate passes if the largest of the m statistics under random sign
flips of whole blocks reaches its own at most ``ALPHA`` of the time), so the false-alarm
rate of a ``none`` campaign is at most ``ALPHA`` by construction, whatever the noise
level, rather than tuned by a closure threshold. A candidate judged alone falls back on
Bonferroni (p × m); the family's p-value is at most about that (by the union bound).

A gain must also exceed ``MIN_GAIN_OVER_NOISE`` of the reference's X (error in noise
units): the resolution of X itself (the noise it is measured in is estimated from the
rest before the motion, to about a tenth), below which no model difference is
meaningful. Judged per block as log-ratios, a candidate that is 1 % better on every
block is "consistent"; without this bar a second effect on top of the first was named
for closing 0.3 % of the gap (the demo's Maxwell branch, then string modes at p = 0.004).
Near the noise floor (X < 1.25) half of the reference's gap above the floor is the bar
instead (``Evidence.least_gain``): a tenth of X asks for most of that gap there, and
all of it at X ≈ 1.11, so no effect could be named on gentle recordings.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import rankdata, wilcoxon

from sim.identify.heldout import CHANNELS, Outputs, block_errors, heldout_excess
from sim.identify.traces import Trace

#: Family-wise false-alarm rate of one decision (after the Bonferroni correction): a
#: ``none`` campaign is answered with an effect at most this often. 0.01 cost the small
#: check its dial gauge (closure 0.97, p = 0.0012 over 12 blocks, × 9 candidates).
ALPHA = 0.05
#: Least improvement of X (held-out error in noise units), as a share of the reference's
#: X, that counts at all: X's own resolution (1 noise unit is known to about 10 %).
MIN_GAIN_OVER_NOISE = 0.1
#: A gain that closes this share of the reference's gap above the noise (X − 1) counts
#: even below X's resolution (``Evidence.least_gain``): most of what separates a model
#: near the noise floor from the floor, not a sliver of it.
MIN_GAP_SHARE = 0.5

__all__ = [
    "ALPHA",
    "MIN_GAIN_OVER_NOISE",
    "MIN_GAP_SHARE",
    "Evidence",
    "block_gains",
    "compare",
    "family_p_values",
    "judge",
]


#: Random sign flips of the blocks' gains for the family's null distribution (``judge``):
#: the Monte Carlo error of a p-value near ALPHA is then ±0.0015.
FLIPS = 20_000
_FLIP_CHUNK = 4000


@dataclass(frozen=True)
class Evidence:
    """How a candidate compares with a reference model on the held-out cycles."""

    x_before: float  # reference's held-out error, noise units (1 = perfect)
    x_after: float  # candidate's
    p_value: float  # one-sided, single test: block gains centred on ≤ 0
    blocks: int
    #: Its p-value as one of the family of candidates judged together (``judge``): the
    #: chance that any of them scores this well under "no effect"; None if judged alone.
    p_family: float | None = None

    @property
    def gain(self) -> float:
        """Drop of X, noise units."""
        return self.x_before - self.x_after

    def corrected_p(self, tests: int) -> float:
        """The family's p-value if judged in one, else Bonferroni's over ``tests``."""
        if self.p_family is not None:
            return self.p_family
        return min(1.0, self.p_value * max(tests, 1))

    @property
    def least_gain(self) -> float:
        """The gain that counts at all: X's resolution, or half the gap above the noise.

        The lesser of a tenth of the reference's X (``MIN_GAIN_OVER_NOISE``) and half of
        what separates it from the noise floor, X − 1 (``MIN_GAP_SHARE``; the lesser
        where X < 1.25). A tenth of X alone asked more than the whole gap of a baseline
        already near the floor: on the other stand's gentle recordings a force gauge
        low-pass took X from 1.12 to 1.02 (the truth's 1.017) at family p 1e-4 and was
        answered ``none``.
        """
        resolution = MIN_GAIN_OVER_NOISE * max(self.x_before, 1.0)
        return min(resolution, MIN_GAP_SHARE * max(self.x_before - 1.0, 0.0))

    def accepted(self, tests: int, alpha: float = ALPHA) -> bool:
        """Evidence of an effect when it was one of ``tests`` candidates."""
        return self.corrected_p(tests) <= alpha and self.gain > 0 and self.gain >= self.least_gain


def p_value_of_gains(gains: np.ndarray) -> float:
    """One-sided p of "block gains are centred on ≤ 0" (Wilcoxon signed-rank)."""
    nonzero = gains[gains != 0.0]
    if nonzero.size < 2:
        return 1.0
    return float(wilcoxon(nonzero, alternative="greater").pvalue)


def block_gains(
    traces: Sequence[Trace],
    before: Sequence[Outputs],
    after: Sequence[Outputs],
    channels: Sequence[str] = CHANNELS,
) -> np.ndarray:
    """Per held-out block: the log of the error ratio, before over after (> 0: better).

    Relative gains: each block counts by how much the candidate improved on it, not by
    how large its error was. A trace whose error neither model explains (a chaotic
    bounce, a form the candidate lacks) has blocks of errors a hundred times the others',
    which drowned a candidate's consistent threefold gain on every other trace (absolute
    gains: p = 0.18 after the correction, relative: see docs/diagnosis.md, "The decision").
    """
    eb, ea = block_errors(traces, before, after, channels=channels)
    return np.log(np.maximum(eb, 1e-300) / np.maximum(ea, 1e-300))


def compare(
    traces: Sequence[Trace],
    before: Sequence[Outputs],
    after: Sequence[Outputs],
    channels: Sequence[str] = CHANNELS,
) -> Evidence:
    """The held-out evidence that ``after`` predicts better than ``before`` (alone).

    ``channels``: the recorded channels judged (both by default).
    """
    gains = block_gains(traces, before, after, channels)
    return Evidence(
        x_before=heldout_excess(traces, before, channels),
        x_after=heldout_excess(traces, after, channels),
        p_value=p_value_of_gains(gains),
        blocks=int(gains.size),
    )


def judge(
    traces: Sequence[Trace],
    before: Sequence[Outputs],
    candidates: dict[str, Sequence[Outputs]],
    flips: int = FLIPS,
) -> dict[str, Evidence]:
    """Every candidate's evidence against ``before``, as one family of tests.

    Each candidate's statistic is its signed-rank sum over the held-out blocks
    (standardised, so candidates with different numbers of non-zero gains compare).
    Under "no effect" every block's gains are symmetric about zero or worse, for all the
    candidates at once, so flipping the signs of whole blocks — the same flip for every
    candidate — draws from the family's null; a candidate's family p-value is the share of
    flips whose *largest* statistic reaches its own (Westfall and Young's single-step
    maxT). The chance that any candidate passes by luck stays at most ``ALPHA``, as with
    Bonferroni, but the candidates' gains are strongly correlated — every refit also
    moves the baseline's parameters, and the blocks where the baseline misses are the
    same for all — so the family counts as fewer than m independent tests, and a real
    effect needs less luck to show (Bonferroni's p × 9 lost a light stick-slip at
    p = 0.0086).
    """
    names = list(candidates)
    if not names:
        return {}
    x_before = heldout_excess(traces, before)
    gains = np.stack([block_gains(traces, before, candidates[n]) for n in names])
    return {
        name: Evidence(
            x_before=x_before,
            x_after=heldout_excess(traces, candidates[name]),
            p_value=p_value_of_gains(g),
            blocks=int(g.size),
            p_family=float(p),
        )
        for name, g, p in zip(names, gains, family_p_values(gains, flips), strict=True)
    }


def family_p_values(gains: np.ndarray, flips: int = FLIPS, seed: int = 0) -> np.ndarray:
    """maxT family p-values of candidates' block gains (candidates × blocks), see ``judge``.

    The flips are a fixed draw (``seed``): the same recordings give the same answer.
    """
    signs = np.sign(gains)
    ranks = np.zeros_like(gains)
    for i in range(gains.shape[0]):
        nonzero = signs[i] != 0
        ranks[i, nonzero] = rankdata(np.abs(gains[i, nonzero]))
    n = (signs != 0).sum(axis=1).astype(np.float64)
    mean = n * (n + 1) / 4
    spread = np.sqrt(n * (n + 1) * (2 * n + 1) / 24)
    usable = n >= 2  # as ``p_value_of_gains``: fewer non-zero gains are no evidence

    def statistics(flip: np.ndarray) -> np.ndarray:  # flip: (F, blocks) of ±1
        positive = ((flip[:, None, :] * signs[None, :, :]) > 0).astype(np.float64)
        w = np.einsum("fmb,mb->fm", positive, ranks)
        z = (w - mean) / np.where(usable, spread, 1.0)
        return np.where(usable, z, -np.inf)

    blocks = gains.shape[1]
    observed = statistics(np.ones((1, blocks)))[0]
    rng = np.random.default_rng(seed)
    largest = np.empty(0)
    for done in range(0, flips, _FLIP_CHUNK):  # in chunks: flips × candidates × blocks
        flip = rng.choice(np.array([-1.0, 1.0]), size=(min(_FLIP_CHUNK, flips - done), blocks))
        largest = np.concatenate([largest, statistics(flip).max(axis=1)])
    hits = np.array([np.count_nonzero(largest >= z) for z in observed])
    return np.where(usable, (hits + 1) / (flips + 1), 1.0)
