"""Start points for the pulley-jump refit, read off the recorded seat changes.

A fibre that re-seats on the pulley changes its effective length by the seat's offset
Δl, and while it is taut the recorded force then sits off the fibre's law by k·Δl:

    r = (F − c·δ̇)/k − (δ₀ + x − n·u) = Δl

(``kernel._segments``: the seat adds to the elongation). Between two slack episodes the
seat cannot move, so r is constant over each taut interval, and its changes across the
episodes are the seat's steps: a toggle between two grooves reads +s, −s, +s …, a fibre
climbing a groove's flank s, s, … up to the flange, then nothing. The refit's start grid
spreads the step over its physical range and takes the two-groove toggle; on the
independently written stand a ratchet of two seats 1 mm down left every grid point in a
basin of the wrong sign (step +3 mm at its bound, closure 0.03, ``none``), while a
start at the steps these offsets show closed 0.8 of the gap (p 10⁻¹⁰). The steps'
onset (how deep an episode must be) is taken just below the shallowest episode that
moved the seat. These are only start points: the local fit and the held-out test still
decide.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sim.identify.fitting import Candidate, grid_axis
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

EFFECT = "fibre_pulley_jump"
#: Slack: the force below this share of the rest tension (as the seat law's own episodes,
#: ``fibre_pulley_jump._start_state``); taut: above ``TAUT_SHARE``, away from the edges.
SLACK_SHARE = 0.05
TAUT_SHARE = 0.3
#: A taut interval shorter than this tells no offset (a bounce between two slack
#: episodes), s.
MIN_TAUT_S = 0.02
#: A change of r counts as a seat step when it exceeds this many times r's robust spread
#: within the intervals on either side (the model's own error there: a skewed channel,
#: a ringing span) …
STEP_SPREADS = 3.0
#: … and exceeds a tenth of the smallest typical step (0.1 mm): below, it is not a start
#: worth a refit.
MIN_STEP_M = 1.0e-5
#: Steps read from several recordings within this share of each other are one start.
SAME_STEP = 0.05
#: A taut law within this share of the fit's stiffness and damping reads the same steps.
SAME_LAW = 0.05
#: The onset is put this share of the way to the shallowest episode that moved the seat.
ONSET_SHARE = 0.8


@dataclass(frozen=True)
class _Episodes:
    """One recording's taut intervals (the first holds the rest seat) and slack episodes."""

    offsets: FloatArray  # r per taut interval, from the first's, m
    spreads: FloatArray  # r's robust spread within each interval, m
    depths: FloatArray  # deepest slack of the episode before each later interval, m
    lengths: FloatArray  # … and its longest unbroken slack, s

    def steps(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The seat's steps (changes of r that stand out), their episodes' depths, lengths."""
        changes = np.diff(self.offsets)
        noise = STEP_SPREADS * np.maximum(self.spreads[:-1], self.spreads[1:])
        moved = np.abs(changes) > np.maximum(noise, MIN_STEP_M)
        return changes[moved], self.depths[moved], self.lengths[moved]


@dataclass(frozen=True)
class _Channels:
    """A recording's fibre geometry and force, as the seat law reads them."""

    stretch: FloatArray  # x − n·u: the elongation less its rest value, m
    rate: FloatArray  # its rate, m/s
    force: FloatArray  # the recorded force (smoothed), N
    slack: BoolArray
    taut: BoolArray
    runs: list[IntArray]  # alternating runs of slack and not-slack samples


def _channels(trace: Trace, nominal: StandParams) -> _Channels:
    n = nominal.projection
    rest_tension = nominal.preload_tension_n
    seg = trace.segments  # the restarts' smoothed channels, computed once per trace
    u_s, v_s, f_s = seg.u_m, seg.v_m_s, seg.force_n
    if np.isfinite(trace.dial_slope) and trace.dial_slope > 0:  # the gauge's own scale
        u_s, v_s = u_s / (trace.dial_slope * n), v_s / (trace.dial_slope * n)
    x = trace.x_m - trace.x_m[0]
    slack = f_s < SLACK_SHARE * rest_tension
    # Runs of slack samples are the episodes; the taut samples between them the intervals.
    edges = np.flatnonzero(np.diff(slack.astype(np.int8))) + 1
    return _Channels(
        x - n * u_s,
        np.gradient(x, 1.0 / trace.rate_hz) - n * v_s,
        f_s,
        slack,
        f_s > TAUT_SHARE * rest_tension,
        np.split(np.arange(slack.size), edges),
    )


def taut_law(traces: Sequence[Trace], nominal: StandParams) -> tuple[float, float] | None:
    """The fibre's stiffness and damping scales that the taut intervals show, or None.

    Between two slack episodes the seat cannot move, so there the force follows the
    fibre's law up to a constant offset per interval: F = k·(x − n·u) + c·(ẋ − n·u̇) + a_j.
    Least squares with an intercept per interval (each interval demeaned) gives k and c
    whatever the seat did. The baseline fit cannot: without a seat it takes the seat's
    steps into k and c. On a light weight of the other stand (a ratchet of 0.74 mm
    seats) it had k ×0.60 and c ×4.0 (the truth ×1.18, ×0.86), and r read with those
    showed no step at all. Training cycles only: these values start a refit.
    """
    rows: list[FloatArray] = []
    forces: list[FloatArray] = []
    for trace in traces:
        ch = _channels(trace, nominal)
        min_taut = int(MIN_TAUT_S * trace.rate_hz)
        # Intervals are runs of taut training samples: a dip of the smoothed force that
        # never reads as slack may still have let the seat move (a snap at the least
        # slack), and an interval split there costs one more intercept, not a bias.
        finite = np.isfinite(ch.stretch) & np.isfinite(ch.rate) & np.isfinite(ch.force)
        use = ch.taut & trace.train & finite  # a lost sample cuts an interval too
        edges = np.flatnonzero(np.diff(use.astype(np.int8))) + 1
        for held in np.split(np.arange(use.size), edges):
            if not use[held[0]] or held.size < min_taut:
                continue
            design = np.column_stack([ch.stretch[held], ch.rate[held]])
            rows.append(design - design.mean(axis=0))
            forces.append(ch.force[held] - ch.force[held].mean())
    if len(rows) < 2:
        return None
    design, force = np.concatenate(rows), np.concatenate(forces)
    (k, c), *_ = np.linalg.lstsq(design, force, rcond=None)
    if not (k > 0 and c > 0):
        return None
    return float(k / nominal.stiffness_n_m), float(c / nominal.damping_n_s_m)


def _episodes(trace: Trace, nominal: StandParams, values: dict[str, float]) -> _Episodes | None:
    """The recording's taut-interval offsets r and its slack episodes (None: < 2 intervals)."""
    k = nominal.stiffness_n_m * values.get("stiffness_scale", 1.0)
    c = nominal.damping_n_s_m * values.get("damping_scale", 1.0)
    ch = _channels(trace, nominal)
    elongation = nominal.preload_tension_n / k + ch.stretch
    r = (ch.force - c * ch.rate) / k - elongation
    slack, taut = ch.slack, ch.taut
    offsets: list[float] = []
    spreads: list[float] = []
    depths: list[float] = []
    lengths: list[float] = []
    depth, length = np.nan, 0.0
    min_taut = int(MIN_TAUT_S * trace.rate_hz)
    for run in ch.runs:
        if slack[run[0]]:
            seat = offsets[-1] - offsets[0] if offsets else 0.0
            episode = float(np.max(-(elongation[run] + seat)))
            depth = episode if np.isnan(depth) else max(depth, episode)
            length = max(length, run.size / trace.rate_hz)
            continue
        held = r[run[taut[run]]]
        if held.size < min_taut:
            continue  # too short to read: its episode counts with the next one
        level = float(np.median(held))
        offsets.append(level)
        spreads.append(1.4826 * float(np.median(np.abs(held - level))))
        if len(offsets) > 1:
            depths.append(depth)
            lengths.append(length)
        depth, length = np.nan, 0.0
    if len(offsets) < 2:
        return None
    rel = np.asarray(offsets) - offsets[0]
    return _Episodes(rel, np.asarray(spreads), np.asarray(depths), np.asarray(lengths))


def seat_probes(
    traces: Sequence[Trace], nominal: StandParams, values: dict[str, float]
) -> list[dict[str, float]]:
    """Start points (``fibre_pulley_jump.*`` values) from the recorded seat steps, or none.

    ``values``: the baseline's fitted parameters (its stiffness and damping scales read r).
    Each recording that shows steps proposes its own: its first step (from the rest
    seat), as a toggle and as a ratchet of as many steps as its last seat is away from
    rest, and that whole climb as one step. A recording whose steps drown in the model's
    error there (a chaotic bounce, a skewed channel) proposes none, or wrong ones that
    the grid then does not keep.

    The steps are read twice: with ``values``' stiffness and damping, and with those the
    taut intervals show (``taut_law``), which the latter starts then carry.
    """
    probes = _read(traces, nominal, values)
    law = taut_law(traces, nominal)
    if law is not None:
        scales = {"stiffness_scale": law[0], "damping_scale": law[1]}
        if any(abs(v / values.get(k, 1.0) - 1.0) > SAME_LAW for k, v in scales.items()):
            probes += [{**scales, **p} for p in _read(traces, nominal, {**values, **scales})]
    return probes


def _read(
    traces: Sequence[Trace], nominal: StandParams, values: dict[str, float]
) -> list[dict[str, float]]:
    """``seat_probes`` read with the stiffness and damping scales of ``values``."""
    params = {p.name: p for p in Candidate.build(EFFECT).params}
    most_seats = int(params[f"{EFFECT}.seats"].scan[-1])  # the flange's highest level
    shapes: list[tuple[float, int]] = []  # step, seats
    moved_depths: list[float] = []
    moved_lengths: list[float] = []
    for trace in traces:
        episodes = _episodes(trace, nominal, values)
        if episodes is None:
            continue
        steps, depths, lengths = episodes.steps()
        if steps.size == 0:
            continue
        step, climb = float(steps[0]), float(episodes.offsets[-1])
        seats = int(np.clip(round(climb / step), 1, most_seats))
        shapes += [(step, 0), (step, seats)]
        if seats > 1:
            shapes.append((climb, 1))  # the whole climb as one step
        moved_depths += [float(d) for d in depths if np.isfinite(d)]
        moved_lengths += [float(t) for t in lengths]
    if not shapes:
        return []
    # What set the episodes that moved the seat apart: their depth, or how long they lay
    # slack (a fibre that needs time to slide out of its groove). Either trigger just
    # below the least that moved it.
    triggers = [
        (ONSET_SHARE * max(0.0, min(moved_depths, default=0.0)), 0.0),
        (0.0, ONSET_SHARE * min(moved_lengths)),
    ]
    # The grid's two sharpest depth scales: a re-seat completes within a fraction of the
    # slack loop (every refit from these starts ended at 0.3 mm or less).
    depth = params[f"{EFFECT}.depth_scale_m"]
    sharp = [depth.to_natural(float(z)) for z in grid_axis(depth, 2)[:2]]
    return [
        {
            f"{EFFECT}.step_m": step,
            f"{EFFECT}.seats": float(seats),
            f"{EFFECT}.onset_m": onset,
            f"{EFFECT}.dwell_s": dwell,
            f"{EFFECT}.depth_scale_m": scale,
        }
        for step, seats in _distinct(shapes)
        for onset, dwell in triggers
        for scale in sharp
    ]


def _distinct(shapes: list[tuple[float, int]]) -> list[tuple[float, int]]:
    """The shapes without repeats (the same seats, a step within ``SAME_STEP`` of another)."""
    kept: list[tuple[float, int]] = []
    for step, seats in shapes:
        if not any(n == seats and abs(s - step) <= SAME_STEP * abs(s) for s, n in kept):
            kept.append((step, seats))
    return kept
