"""Multiple shooting from measured states: short simulations that restart on the data.

With the light weight in quick motions the weight bounces on a slack fibre and the model
is chaotic (``sim.sensitivity``): an open-loop run from rest drifts away from any
recording after a few bounces whatever the parameters, so output error over a whole
recording measures chaos, not the model. Here every trace is cut into *segments*; each
is simulated from the state *measured* at its start, so a prediction error can grow for
at most one segment and the fit compares the model's short-term dynamics with the data.

* Restarts only where they are needed: a boundary is set only if the fibre went slack
  since the previous one, because chaos needs slack and snatch. A taut stretch forgets
  nothing chaotic, and a restart there only adds the state estimate's noise (measured:
  a slow light-weight trace, true model, held-out error 0.042 restarted every 0.25 s,
  0.033 in one piece). A trace that never goes slack is one open-loop run.
* Segment bodies are at least ``SEGMENT_S`` long. Each boundary is moved (by up to a
  quarter of a segment) to where the force changes least, on a taut fibre, at the start
  of its run (the warm-up before the body), so no segment starts in a snatch, where a
  local fit of the state would be biased, nor in slack, which hides the effects' states
  (string sag, pulley seat). Measured: moving by up to half a segment lost a heavy-weight
  campaign's pulley-seat steps (diagnosed ``none``).
* Each segment after the first starts ``WARMUP_S`` before its body: the warm-up lets the
  effects' unmeasured states and the gauge filter settle, gives a skewed channel its
  history, and is not scored (the previous segment's body covers those samples).
* The start state: u and v from a local cubic least-squares (Savitzky–Golay) fit of the
  recorded u over ±``STATE_HALF_WIDTH_S``; F likewise smoothed. A candidate's measurement
  effect is inverted first (the dial gauge's gain and offset, the displacement channel's
  skew), so the state is the true one the candidate implies. The model does that
  (``sim.model.Model.run_segments``), and sets the effects' own states: quasi-static
  values, and for the Maxwell branch its response to the measured elongation history.
  Then the model refines u and v over the warm-up, from both gauges, the cubic fit as
  prior (``sim.physics.refine``: the weight rings on a taut fibre, and the fit's
  velocity error rang through every segment).
  Those the gauges cannot see at a start (string modes, LuGre bristle) carry over from
  the previous segment's run instead. The pulley seat follows the recorded slack
  episodes, at the start and inside every run (``kernel.measured_seats``).
* The first segment starts at sample 0 from static rest, exactly as an open-loop run.

Held-out cycles are then judged on segment predictions as well; that is fair because
every start state comes from measurements, never from a fitted trajectory.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.signal import savgol_coeffs, savgol_filter

from sim.model import Restarts, StartWindow

if TYPE_CHECKING:  # the trace holds its segments; only its type is needed here
    from sim.identify.traces import Trace

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Segment body length, s (see the module docstring; chosen by measurement, see tests).
SEGMENT_S = 0.25
#: Unscored lead-in of every segment after the first, s.
WARMUP_S = 0.025
#: Half width of the local cubic fit that estimates u and v at a segment start, s.
STATE_HALF_WIDTH_S = 0.005
#: Smoothing of |dF/dt| when choosing boundaries, s.
CALM_WINDOW_S = 0.02
#: The fibre counts as slack below this share of the trace's median force.
SLACK_SHARE = 0.1


@dataclass(frozen=True)
class Segments:
    """How one trace is cut, and its measured states at the segment starts.

    Half of it is what the model takes as ``sim.model.Restarts`` (``restarts``: starts,
    lengths, the smoothed channels, the dial slope); the other half how the runs tile the
    trace (body, seg_of, offset), which only the diagnosis needs.

    Attributes
    ----------
    starts, lengths
        First simulated sample and number of simulated samples per segment.
    body
        First scored sample per segment (bodies tile the trace: body[k + 1] ends k).
    u_m, v_m_s, force_n
        Smoothed recorded u, its rate and F at every sample (state estimates).
    dial_slope
        du/dx at constant force on a calm taut fibre (``dial_slope``), NaN if unknown.
    seg_of, offset
        For every sample of the trace: its segment and index inside that segment's run.
    window
        The recorded channels over each later segment's warm-up, which refine its start
        (``sim.model.StartWindow``); None: the starts stay as estimated.
    """

    starts: IntArray
    lengths: IntArray
    body: IntArray
    u_m: FloatArray
    v_m_s: FloatArray
    force_n: FloatArray
    seg_of: IntArray
    offset: IntArray
    dial_slope: float = float("nan")
    window: StartWindow | None = None

    @property
    def count(self) -> int:
        """Number of segments."""
        return int(self.starts.size)

    @property
    def restarts(self) -> Restarts:
        """The segment starts and measured channels, as the model takes them."""
        return self.restarts_ahead(0)

    def restarts_ahead(self, lookahead: int) -> Restarts:
        """``restarts`` with every run going on ``lookahead`` samples past its own end.

        A channel recorded early reads ahead of the simulated run; a run that ended with
        its body held its last value there (a force recorded 4 ms early: 5× the held-out
        error of one open-loop run).
        """
        lengths = np.minimum(self.lengths + lookahead, self.seg_of.size - self.starts)
        return Restarts(
            self.starts, lengths, self.u_m, self.v_m_s, self.force_n, self.dial_slope,
            self.window,
        )  # fmt: skip

    def assemble(self, runs: FloatArray) -> FloatArray:
        """Segment runs (sets, segments, samples) → one series per set (sets, N)."""
        return np.asarray(runs[:, self.seg_of, self.offset])

    def covering(
        self, samples: IntArray, lookahead: int = 0
    ) -> tuple[Restarts, IntArray, IntArray]:
        """Restarts of only the segments whose bodies hold ``samples``; per sample its run.

        For each sample: the run it lies in (position among those kept) and its index in
        that run. Each segment restarts from measured states, so leaving out the others changes
        nothing in these runs, and a run is causal, so it ends ``lookahead`` samples after
        its last sample asked for (a channel recorded early reads ahead). A fit scored on
        the training cycles simulates about two thirds of the samples.
        """
        keep = np.unique(self.seg_of[samples])
        position = np.searchsorted(keep, self.seg_of[samples]).astype(np.int64)
        offset = self.offset[samples]
        lengths = np.zeros(keep.size, dtype=np.int64)
        np.maximum.at(lengths, position, offset + 1 + lookahead)
        lengths = np.minimum(lengths, self.seg_of.size - self.starts[keep])
        restarts = Restarts(
            self.starts[keep], lengths, self.u_m, self.v_m_s, self.force_n, self.dial_slope,
            self.window,
        )  # fmt: skip
        return restarts, position, offset

    def leading(self, samples: IntArray, lookahead: int = 0) -> tuple[Restarts, IntArray, IntArray]:
        """As ``covering``, but every segment from the first up to the last that holds one.

        For a model whose states carry from segment to segment (``Model.chained``): the
        runs before a sample are its history, and only the runs after the last sample
        asked for can be left out. The last run ends ``lookahead`` samples after its last
        sample asked for.
        """
        last = int(self.seg_of[samples].max()) + 1 if samples.size else 1
        position = self.seg_of[samples].astype(np.int64)
        offset = self.offset[samples]
        lengths = np.minimum(self.lengths[:last] + lookahead, self.seg_of.size - self.starts[:last])
        tail = int(offset[position == last - 1].max()) + 1 + lookahead if samples.size else 1
        lengths[-1] = min(int(lengths[-1]), tail)
        restarts = Restarts(
            self.starts[:last], lengths, self.u_m, self.v_m_s, self.force_n, self.dial_slope,
            self.window,
        )  # fmt: skip
        return restarts, position, offset


def _filled(series: FloatArray) -> FloatArray:
    """Lost samples (NaN) linearly interpolated, so smoothing can run over them."""
    ok = np.isfinite(series)
    if ok.all():
        return series
    idx = np.arange(series.size)
    return np.interp(idx, idx[ok], series[ok])


def _boundaries(force: FloatArray, rate_hz: float, segment_s: float, warm: int) -> IntArray:
    """Body starts: every ``segment_s`` after slack, each where its run starts calmest."""
    n = force.size
    step = max(round(segment_s * rate_hz), 4)
    if n < 2 * step:
        return np.array([0], dtype=np.int64)
    width = max(1, int(CALM_WINDOW_S * rate_hz))
    rough = np.convolve(np.abs(np.gradient(force)), np.ones(width) / width, mode="same")
    # Prefer a taut fibre: slack hides the effects' states (string sag, pulley seat).
    rough = rough + np.where(force > 0.5 * np.median(force), 0.0, np.abs(rough).max())
    # Judge a body start by its run's start, the warm-up earlier.
    rough = np.concatenate([np.full(warm, rough[0]), rough[: n - warm]])
    reach = step // 4
    slack = force < SLACK_SHARE * np.median(force)
    bounds = [0]
    for nominal in range(step, n - step // 2, step):
        lo, hi = max(nominal - reach, bounds[-1] + step // 2), min(nominal + reach, n - step // 2)
        if hi <= lo or not slack[bounds[-1] : lo].any():
            continue
        bounds.append(lo + int(np.argmin(rough[lo:hi])))
    return np.asarray(bounds, dtype=np.int64)


def segment_trace(
    trace: Trace,
    segment_s: float = SEGMENT_S,
    warmup_s: float = WARMUP_S,
    half_width_s: float = STATE_HALF_WIDTH_S,
) -> Segments:
    """Cut a trace into segments and estimate the measured state along it."""
    rate = trace.rate_hz
    u_s, v_s, f_s, _ = _smoothed(trace, half_width_s)
    warm = round(warmup_s * rate)
    body = _boundaries(f_s, rate, segment_s, warm)
    starts = np.where(body > 0, np.maximum(body - warm, 0), 0).astype(np.int64)
    ends = np.append(body[1:], trace.samples)
    lengths = (ends - starts).astype(np.int64)
    seg_of = np.repeat(np.arange(body.size), ends - body).astype(np.int64)
    offset = (np.arange(trace.samples) - starts[seg_of]).astype(np.int64)
    slope = trace.dial_slope
    if not np.isfinite(slope):
        slope = dial_slope([trace])
    window = start_window(trace, warm, half_width_s)
    return Segments(starts, lengths, body, u_s, v_s, f_s, seg_of, offset, slope, window)


def start_window(trace: Trace, samples: int, half_width_s: float) -> StartWindow:
    """The recorded channels that refine each start over ``samples`` after it.

    The prior spreads are the local cubic fit's own: its smoothing and differentiating
    weights' norms times the larger of the gauge noise and the fit's residual spread
    there (where the cubic cannot follow the motion, a ringing say, its estimate is
    worth less than the noise alone says).
    """
    half = max(2, round(half_width_s * trace.rate_hz))
    window = 2 * half + 1
    order = 3 if window > 4 else window - 1
    u = _filled(trace.u_m)
    residual = u - savgol_filter(u, window, order, mode="interp")
    local = np.convolve(residual**2, np.ones(window) / window, mode="same")
    spread = np.maximum(trace.noise_u_m, np.sqrt(local * window / max(window - order - 1, 1)))
    level = savgol_coeffs(window, order, use="dot")
    rate = savgol_coeffs(window, order, deriv=1, delta=1.0 / trace.rate_hz, use="dot")
    return StartWindow(
        samples,
        u,
        _filled(trace.force_n),
        trace.present,
        trace.noise_u_m,
        trace.noise_force_n,
        spread * float(np.linalg.norm(level)),
        spread * float(np.linalg.norm(rate)),
        u - residual,
    )


def _smoothed(
    trace: Trace, half_width_s: float = STATE_HALF_WIDTH_S
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """u, du/dt, F and dF/dt from a local cubic fit over ±half_width_s (lost samples bridged)."""
    rate = trace.rate_hz
    u = _filled(trace.u_m)
    f = _filled(trace.force_n)
    half = max(2, round(half_width_s * rate))
    window = 2 * half + 1
    order = 3 if window > 4 else window - 1
    u_s = savgol_filter(u, window, order, mode="interp")
    v_s = savgol_filter(u, window, order, deriv=1, delta=1.0 / rate, mode="interp")
    f_s = savgol_filter(f, window, order, mode="interp")
    f_rate = savgol_filter(f, window, order, deriv=1, delta=1.0 / rate, mode="interp")
    return u_s, v_s, f_s, f_rate


#: Samples with |dF/dt| below this share of its largest value count as calm.
CALM_SHARE = 0.05
#: … and with the drive slower than this share of its top speed.
SLOW_SHARE = 0.2


def dial_slope(traces: Sequence[Trace]) -> float:
    """How far the dial gauge's u moves per metre of drive at constant fibre force.

    On a taut fibre whose force is calm the weight follows the drive quasi-statically:
    u = (δ₀ + x − F/k)/n, whatever the friction (F is the measured tension itself). So a
    least-squares fit u ≈ a·x + b·F + c_trace over those samples of all traces (one
    gauge, one slope; each trace its own zero) gives a = G/n, G the dial gauge's scale
    against the drive encoder — a gauge that reads 10 % high shows a = 1.1/n — without
    knowing k (b absorbs it). Samples where the drive moves fast are left out: there a
    channel skewed in time puts v·Δt into u (a 3 ms skew biased G by 1 % on quick
    motions; below a fifth of the top speed by a few 0.01 %), and so are samples after
    the fibre first went slack. The model restarts
    segments from u/G (``sim.model.Restarts``), so a gauge error stays in the u channel
    instead of becoming a wrong elongation, hundreds of newtons, in F. NaN with too few
    such samples or too little drive travel among them.
    """
    columns: list[FloatArray] = []
    targets: list[FloatArray] = []
    blocks: list[int] = []
    for trace in traces:
        u_s, _, f_s, f_rate = _smoothed(trace)
        x = trace.x_m - trace.x_m[0]
        taut = f_s > 0.5 * np.median(f_s)
        calm = np.abs(f_rate) < CALM_SHARE * np.max(np.abs(f_rate))
        drive_rate = np.abs(np.gradient(x))
        slow = drive_rate < SLOW_SHARE * np.max(drive_rate)
        # Only before the fibre first goes slack: afterwards the weight's position for a
        # given drive position can depend on what slack did (a fibre re-seated on the
        # pulley shifted u by 1.4 mm and biased G by 3 % in a validation campaign).
        first_slack = np.flatnonzero(f_s < SLACK_SHARE * np.median(f_s))
        before = np.arange(x.size) < (first_slack[0] if first_slack.size else x.size)
        sel = taut & calm & slow & before & trace.present & np.isfinite(trace.u_m)
        travel = float(np.ptp(x))
        if np.count_nonzero(sel) < 200 or travel <= 0 or np.ptp(x[sel]) < 0.3 * travel:
            continue
        columns.append(np.column_stack([x[sel], f_s[sel]]))
        targets.append(u_s[sel])
        blocks.append(int(np.count_nonzero(sel)))
    if not blocks:
        return float("nan")
    zeros = np.zeros((sum(blocks), len(blocks)))
    row = 0
    for j, count in enumerate(blocks):
        zeros[row : row + count, j] = 1.0
        row += count
    design = np.column_stack([np.concatenate(columns), zeros])
    coef, *_ = np.linalg.lstsq(design, np.concatenate(targets), rcond=None)
    return float(coef[0])
