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

Each candidate is also judged in each channel alone, in the same family (``judge``): a
block's errors summed over u and F let the channel the reference misses most decide
alone, and a gain in the other one — a relaxation branch that predicts the force better
behind a dial gauge whose form leaves u at 7 noise units — was lost in u's scatter. The
family's flips hold all those statistics, so the false-alarm rate stays ``ALPHA``; a
channel's gain must reach that channel's own resolution, and X pooled must not worsen.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

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
    "ChannelEvidence",
    "Evidence",
    "block_gains",
    "compare",
    "family_p_values",
    "judge",
    "least_gain_of",
]


#: Random sign flips of the blocks' gains for the family's null distribution (``judge``):
#: the Monte Carlo error of a p-value near ALPHA is then ±0.0015.
FLIPS = 20_000
_FLIP_CHUNK = 4000


@dataclass(frozen=True)
class ChannelEvidence:
    """A candidate judged in one recorded channel alone (``judge``)."""

    channel: str
    x_before: float
    x_after: float
    p_family: float

    def accepted(self, alpha: float = ALPHA) -> bool:
        """A consistent gain in this channel of at least its own X's resolution."""
        gain = self.x_before - self.x_after
        return self.p_family <= alpha and gain > 0 and gain >= least_gain_of(self.x_before)


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
    #: The same candidate judged in each channel alone, in the same family (``judge``).
    channels: tuple[ChannelEvidence, ...] = field(default=())

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

        See ``least_gain_of``.
        """
        return least_gain_of(self.x_before)

    def accepted(self, tests: int, alpha: float = ALPHA) -> bool:
        """Evidence of an effect when it was one of ``tests`` candidates.

        Pooled over the channels, or in one channel alone (judged in the family) where X
        pooled does not worsen.
        """
        if self.gain <= 0:
            return False
        pooled = self.corrected_p(tests) <= alpha and self.gain >= self.least_gain
        return pooled or any(c.accepted(alpha) for c in self.channels)


def least_gain_of(x_before: float) -> float:
    """The gain of X (or of one channel's X) that counts, from the reference's X.

    The lesser of a tenth of the reference's X (``MIN_GAIN_OVER_NOISE``) and half of
    what separates it from the noise floor, X − 1 (``MIN_GAP_SHARE``; the lesser where
    X < 1.25). A tenth of X alone asked more than the whole gap of a baseline already
    near the floor: on the other stand's gentle recordings a force gauge low-pass took X
    from 1.12 to 1.02 (the truth's 1.017) at family p 1e-4 and was answered ``none``.
    """
    resolution = MIN_GAIN_OVER_NOISE * max(x_before, 1.0)
    return min(resolution, MIN_GAP_SHARE * max(x_before - 1.0, 0.0))


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
    flips whose *largest* statistic reaches its own (Westfall and Young's maxT, step-down:
    ``family_p_values``). The chance that any candidate passes by luck stays at most
    ``ALPHA``, as with Bonferroni, but the candidates' gains are strongly correlated — every
    refit also moves the baseline's parameters, and the blocks where the baseline misses
    are the same for all — so the family counts as fewer than m independent tests, and a
    real effect needs less luck to show (Bonferroni's p × 9 lost a light stick-slip at
    p = 0.0086).

    The family also holds each candidate judged in u alone and in F alone (the same
    flips): summed over the channels, a block's error is the channel the reference
    misses most, and a gain in the other was lost in its scatter. ``Evidence.channels``
    carries those; the candidate's ``p_family`` is its pooled one.
    """
    names = list(candidates)
    if not names:
        return {}
    x_before = heldout_excess(traces, before)
    # Rows: each candidate pooled, then in each channel alone; one family of them all.
    views = [CHANNELS, *((c,) for c in CHANNELS)]
    gains = np.stack([block_gains(traces, before, candidates[n], v) for n in names for v in views])
    p = family_p_values(gains, flips).reshape(len(names), len(views))
    x_channel = {c: heldout_excess(traces, before, (c,)) for c in CHANNELS}
    out = {}
    for k, name in enumerate(names):
        channels = tuple(
            ChannelEvidence(c, x_channel[c], heldout_excess(traces, candidates[name], (c,)),
                            float(p[k, 1 + j]))
            for j, c in enumerate(CHANNELS)
        )  # fmt: skip
        out[name] = Evidence(
            x_before=x_before,
            x_after=heldout_excess(traces, candidates[name]),
            p_value=p_value_of_gains(gains[k * len(views)]),
            blocks=int(gains.shape[1]),
            p_family=float(p[k, 0]),
            channels=channels,
        )
    return out


def family_p_values(gains: np.ndarray, flips: int = FLIPS, seed: int = 0) -> np.ndarray:
    """maxT family p-values of candidates' block gains (candidates × blocks), see ``judge``.

    Step-down (Westfall and Young's Algorithm 2.8): the strongest statistic is compared
    with the largest of all under the flips, the next with the largest of those not
    stronger than it, and so on, the p-values kept non-decreasing in that order. The
    family-wise rate is that of the single-step maxT; a candidate is not held back by
    stronger ones the test has already set apart (a pulley's inertia behind a gauge
    low-pass, family p 0.060 beside three statistics of each other candidate).
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
    order = np.argsort(-observed, kind="stable")  # strongest first
    rng = np.random.default_rng(seed)
    hits = np.zeros(order.size)
    for done in range(0, flips, _FLIP_CHUNK):  # in chunks: flips × candidates × blocks
        flip = rng.choice(np.array([-1.0, 1.0]), size=(min(_FLIP_CHUNK, flips - done), blocks))
        ordered = statistics(flip)[:, order]
        # Largest over each statistic and every weaker one (a running max from the end).
        successive = np.maximum.accumulate(ordered[:, ::-1], axis=1)[:, ::-1]
        hits += np.count_nonzero(successive >= observed[order], axis=0)
    stepped = np.maximum.accumulate((hits + 1) / (flips + 1))
    p = np.empty(order.size)
    p[order] = stepped
    return np.where(usable, p, 1.0)
