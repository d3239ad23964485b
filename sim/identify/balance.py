"""The stand's two balances read off the recordings: what force or tension is missing.

A term the model lacks shows in the model's output error only through the stand's
dynamics, and a light weight's bounces make that error chaotic. The balances themselves
are instantaneous: with the recorded (low-passed) u, x and F,

* the fibre's law: g = F − (k·e + c·ė), e = T₀/k + x − n·u, on a taut fibre;
* the weight's balance: f = m·ü − n·F + m·g·sin α + F_f(u̇), while it slides;

are zero but for noise on a stand the baseline describes (the equation error of SINDy's
regression; Brunton, Proctor and Kutz 2016). A missing term appears where it acts
(``signature``'s routes): a force on the weight in f; a tension in the fibre's law in g;
a force reading's error d in both, as (d, −n·d); a displacement reading's error w as
(k·n·w + c·n·ẇ, m·ẅ). So each library term has a column in each balance; a variant's
terms and the baseline's own parameters (k, c, the friction's scale, a constant force:
what a baseline fit may have taken from the term) are fitted by STLSQ on the training
cycles and judged on the held-out cycles' blocks, like every candidate.

The balances know no candidate effect, so they describe a gap only where none is named.
Each balance is in units of its own noise, its spread over the rest before the motion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import median_filter
from scipy.signal import butter, sosfiltfilt

from sim.identify.heldout import Outputs, held_out_blocks
from sim.identify.signature import (
    DRIFT_ORDERS,
    POSITION_ORDERS,
    THRESHOLD_NOISE,
    VELOCITY_SCALES_M_S,
    BalanceSeries,
    _legendre,
    _mode_response,
    stlsq,
)
from sim.identify.traces import Trace
from sim.params import StandParams

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

__all__ = ["BALANCE_VARIANTS", "BalanceFit", "FibreLaw", "fibre_law", "fit_balances"]

#: The recorded channels are low-passed (zero phase) here before they are
#: differentiated: the weight's acceleration from a 5 µm dial gauge is noise above it.
LOWPASS_HZ = 100.0
#: Modes of the resonance library, Hz (below the low-pass, a third apart: a mode
#: between two is fitted by both), and their damping ratios.
BALANCE_MODES_HZ = (15.0, 20.0, 27.0, 36.0, 48.0, 64.0)
BALANCE_MODE_ZETAS = (0.03, 0.1)
#: A force sample this many noise spreads off its neighbours' median is a spike (a loose
#: connector's), dropped before the low-pass smears it over its neighbours: one 10 N
#: spike filtered at 100 Hz leaves ±2 N over 20 samples in both balances.
SPIKE_SPREADS = 8.0
#: The weight counts as sliding above this speed (a stuck weight's friction is whatever
#: holds it, which no law gives), m/s.
SLIDING_M_S = 5e-3
#: The rest before the motion whose spread is each balance's noise, s (after the
#: low-pass's start-up).
REST_S = (0.05, 0.4)
#: The kinds and where they act, as ``signature.VARIANTS`` (``u+F``: a physical term).
BALANCE_VARIANTS = (
    ("position", "u+F"), ("position", "u"), ("strain", "u+F"), ("velocity", "u+F"),
    ("velocity", "u"), ("resonance", "u+F"), ("resonance", "F"), ("drift", "u"), ("drift", "F"),
)  # fmt: skip


@dataclass
class _Balances:
    """One trace's balances and what the library is made of (low-passed, SI)."""

    u: FloatArray
    v: FloatArray
    x: FloatArray
    force: FloatArray
    tension: FloatArray  # the model's, noise-free
    e: FloatArray
    e_rate: FloatArray
    friction: FloatArray
    g: FloatArray
    f: FloatArray
    use_g: BoolArray
    use_f: BoolArray
    noise_g: float
    noise_f: float


def _lowpass(series: FloatArray, rate_hz: float) -> FloatArray:
    ok = np.isfinite(series)
    idx = np.arange(series.size)
    filled = np.interp(idx, idx[ok], series[ok]) if not ok.all() else series
    if 0.45 * rate_hz <= LOWPASS_HZ:
        return np.asarray(filled, dtype=np.float64)
    sos = butter(4, LOWPASS_HZ / (rate_hz / 2), output="sos")
    return np.asarray(sosfiltfilt(sos, filled, padtype="constant"), dtype=np.float64)


def _spikes(force: FloatArray, noise: float) -> BoolArray:
    """Samples that stand ``SPIKE_SPREADS`` noise spreads off their neighbours' median."""
    filled = np.where(np.isfinite(force), force, np.nanmedian(force))
    local = median_filter(filled, size=5, mode="nearest")
    return np.asarray(np.abs(filled - local) > SPIKE_SPREADS * max(noise, 1e-9))


@dataclass(frozen=True)
class _Equations:
    """The two balances' parts from one set of channels (low-passed, SI)."""

    u: FloatArray
    v: FloatArray
    x: FloatArray
    force: FloatArray
    e: FloatArray
    e_rate: FloatArray
    friction: FloatArray
    g: FloatArray
    f: FloatArray


def _equations(
    tr: Trace, u_m: FloatArray, force_n: FloatArray, nominal: StandParams, values: dict[str, float]
) -> _Equations:
    """The fibre's law and the weight's balance with these u and F and the trace's x."""
    rate, n = tr.rate_hz, nominal.projection
    k = nominal.stiffness_n_m * values.get("stiffness_scale", 1.0)
    c = nominal.damping_n_s_m * values.get("damping_scale", 1.0)
    gauge = tr.dial_slope * n if np.isfinite(tr.dial_slope) else 1.0  # the dial's scale
    u = _lowpass(u_m, rate) / gauge
    x = _lowpass(tr.x_m - tr.x_m[0], rate)
    force = _lowpass(force_n, rate)
    v = np.gradient(u, 1.0 / rate)
    a = np.gradient(v, 1.0 / rate)
    e = nominal.preload_tension_n / k + x - n * u
    e_rate = np.gradient(x, 1.0 / rate) - n * v
    normal = nominal.normal_force_n * values.get("friction_scale", 1.0)
    friction = (
        nominal.friction.force_n(v, normal) if nominal.friction is not None else np.zeros_like(v)
    )
    g = force - (k * e + c * e_rate)
    f = tr.mass_kg * a - n * force + nominal.gravity_along_n + friction
    return _Equations(u, v, x, force, e, e_rate, friction, g, f)


def _near(marks: BoolArray, reach: int) -> BoolArray:
    """Samples within ``reach`` of a marked one."""
    return np.convolve(marks, np.ones(2 * reach + 1), mode="same").astype(bool)


@dataclass(frozen=True)
class FibreLaw:
    """The fibre's law's parts on one trace (low-passed, SI) and where it can be read."""

    e: FloatArray  # elongation, T₀/k + x − n·u
    e_rate: FloatArray
    force: FloatArray
    usable: BoolArray  # taut, measured, inside the cycles, away from a segment's restart


def fibre_law(
    tr: Trace, nominal: StandParams, values: dict[str, float], model: Outputs | None = None
) -> FibreLaw:
    """The fibre's law read off the recording (or, with ``model``, off the model's outputs).

    The same low-pass, spike removal and masks as the balances: the recorded force's
    spikes and lost samples are bridged and their neighbourhood dropped in both, and so
    is a segment restart's (the model's runs join there with a step).
    """
    spikes = _spikes(tr.force_n, tr.noise_force_n)
    if model is None:
        q = _equations(tr, tr.u_m, np.where(spikes, np.nan, tr.force_n), nominal, values)
    else:
        q = _equations(tr, model.u_m, model.force_n, nominal, values)
    return FibreLaw(q.e, q.e_rate, q.force, _measured(tr, spikes) & _taut(q) & (tr.cycle >= 0))


def _measured(tr: Trace, spikes: BoolArray) -> BoolArray:
    """Samples away from a lost sample, a spike or a segment's restart.

    Lost samples and spikes were bridged before the low-pass: their neighbourhood is
    interpolation, not measurement; a restart's step rings through the low-pass.
    """
    reach = int(tr.rate_hz / LOWPASS_HZ)
    joins = np.zeros(tr.samples, dtype=bool)
    joins[tr.segments.body[1:]] = True
    return ~_near(~tr.present | spikes, reach) & ~_near(joins, 3 * reach)


def _taut(q: _Equations) -> BoolArray:
    return np.asarray((q.force > 0.2 * np.median(q.force)) & (q.e > 0))


def _balances(
    tr: Trace, nominal: StandParams, values: dict[str, float], model: Outputs
) -> _Balances:
    """The recorded balances less the model's own, each through the same low-pass.

    The model's outputs do not balance exactly either: the low-pass and the numerical
    derivatives bend a snatch, the two spans and the pulley are one spring here, and the
    dial's scale is an estimate (off by 5·10⁻⁵, the stiff fibre turns it into 0.8 N·u/span
    in g). On the model's own recordings with noise alone, a position term then passed
    at p 0.0004; with the scale refitted beside k and c instead, a resonance term
    closing 15–18 % of g passed at p 0.003–0.03. What the model
    leaves in the balances through the same steps is no missing force; its difference to
    the recorded one is. Around each segment restart (the runs join there with a step)
    the model's balance is not used.
    """
    rate = tr.rate_hz
    spikes = _spikes(tr.force_n, tr.noise_force_n)
    rec = _equations(tr, tr.u_m, np.where(spikes, np.nan, tr.force_n), nominal, values)
    own = _equations(tr, model.u_m, model.force_n, nominal, values)
    g, f = rec.g - own.g, rec.f - own.f
    present = _measured(tr, spikes)
    use_g = present & _taut(rec) & _taut(own)
    use_f = present & (np.abs(rec.v) > SLIDING_M_S) & (np.abs(own.v) > SLIDING_M_S)
    rest = slice(int(REST_S[0] * rate), max(int(REST_S[1] * rate), int(REST_S[0] * rate) + 10))
    noise_g = float(np.std(g[rest])) or 1.0
    noise_f = float(np.std(f[rest])) or 1.0
    tension = _lowpass(model.force_n, rate)
    return _Balances(rec.u, rec.v, rec.x, rec.force, tension, rec.e, rec.e_rate, rec.friction,
                     g, f, use_g, use_f, noise_g, noise_f)  # fmt: skip


@dataclass(frozen=True)
class _Column:
    name: str
    unit: str
    route: str  # "weight", "tension", "u", "F", or "base" (the baseline's own)


class _BalanceLibrary:
    """The terms of every kind as columns of the two balances, trace by trace."""

    def __init__(
        self,
        traces: Sequence[Trace],
        balances: Sequence[_Balances],
        nominal: StandParams,
        values: dict[str, float],
    ) -> None:
        self.traces, self.balances = traces, balances
        self.n = nominal.projection
        self.k = nominal.stiffness_n_m * values.get("stiffness_scale", 1.0)
        self.c = nominal.damping_n_s_m * values.get("damping_scale", 1.0)
        self.radius = nominal.pulley_radius_m
        self.u_span = max([float(np.ptp(b.u)) for b in balances] + [1e-6])
        self.v_top = max([float(np.max(np.abs(b.v))) for b in balances] + [1e-6])
        self.t_ref = float(np.median(np.concatenate([b.tension for b in balances]))) or 1.0
        self._cache: dict[tuple[str, int], tuple[list[_Column], FloatArray, FloatArray]] = {}

    def columns(self, kind: str, i: int) -> tuple[list[_Column], FloatArray, FloatArray]:
        """The kind's terms on trace ``i``: their names, and their (g, f) columns."""
        key = (kind, i)
        if key not in self._cache:
            self._cache[key] = self._columns(kind, i)
        return self._cache[key]

    def _columns(self, kind: str, i: int) -> tuple[list[_Column], FloatArray, FloatArray]:
        tr, b = self.traces[i], self.balances[i]
        names: list[_Column] = []
        g_cols: list[FloatArray] = []
        f_cols: list[FloatArray] = []
        zero = np.zeros(tr.samples)

        def add(name: str, unit: str, route: str, series: FloatArray) -> None:
            names.append(_Column(name, unit, route))
            if route in ("weight",):
                g_cols.append(zero)
                f_cols.append(series)
            elif route in ("tension",):
                g_cols.append(series)
                f_cols.append(zero)
            elif route == "F":  # the reading F = T + d
                g_cols.append(series)
                f_cols.append(-self.n * series)
            elif route == "u":  # the reading u = u_true + w
                rate = tr.rate_hz
                w_rate = np.gradient(series, 1.0 / rate)
                g_cols.append(self.k * self.n * series + self.c * self.n * w_rate)
                f_cols.append(tr.mass_kg * np.gradient(w_rate, 1.0 / rate))
            else:  # the baseline's own: (g, f) given as a pair by the caller
                raise ValueError(route)

        z = 2 * b.u / self.u_span - 1
        span = f"{self.u_span * 1e3:.3g} mm"
        if kind == "position":
            for o in POSITION_ORDERS:
                add(f"P{o}(u/{span})", "N", "weight", _legendre(z, o))
            for o in (2, 3):
                add(f"P{o}(u/{span})", "m", "u", _legendre(z, o))
            turn = b.x / self.radius
            for h in (1, 2):
                add(f"sin({h}·x/r)", "N", "tension", np.sin(h * turn))
                add(f"cos({h}·x/r)", "N", "tension", np.cos(h * turn))
        elif kind == "strain":
            for p in (2, 3):
                add(f"(T/{self.t_ref:.3g} N)^{p}", "N", "tension",
                    (np.maximum(b.tension, 0.0) / self.t_ref) ** p)  # fmt: skip
        elif kind == "velocity":
            vt = f"{self.v_top:.3g} m/s"
            add(f"v/{vt}", "N", "weight", b.v / self.v_top)
            add(f"v·|v|/({vt})²", "N", "weight", b.v * np.abs(b.v) / self.v_top**2)
            for s in VELOCITY_SCALES_M_S:
                add(f"tanh(v/{s:g} m/s)", "N", "weight", np.tanh(b.v / s))
            for s in VELOCITY_SCALES_M_S:  # a gauge's backlash: the reading lags the motion
                add(f"tanh(v/{s:g} m/s)", "m", "u", np.tanh(b.v / s))
            add(f"v/{vt}", "m", "u", b.v / self.v_top)  # … or its own dynamics do
        elif kind == "resonance":
            for hz in BALANCE_MODES_HZ:
                for zeta in BALANCE_MODE_ZETAS:
                    mode = _mode_response(b.tension, hz, tr.rate_hz, zeta)
                    label = f"mode {hz:g} Hz ζ {zeta:g} of T"
                    add(label, "N", "tension", mode)
                    add(label, "N", "F", mode)
        elif kind == "drift":
            t = np.linspace(-1.0, 1.0, tr.samples)
            for j, other in enumerate(self.traces):
                for o in DRIFT_ORDERS:
                    poly = _legendre(t, o) if j == i else zero
                    add(f"{other.name}: P{o}(t)", "m", "u", poly)
                    add(f"{other.name}: P{o}(t)", "N", "F", poly)
        elif kind == "base":
            # k, c, the friction's scale, a constant force along the guide (the incline),
            # and each recording's own tension offset (its preload, its gauge's zero).
            names += [_Column(nm, "", "base") for nm in ("k·e", "c·ė", "friction", "force")]
            g_cols += [self.k * b.e, self.c * b.e_rate, zero, zero]
            f_cols += [zero, zero, b.friction, np.ones(tr.samples)]
            for j, other in enumerate(self.traces):
                names.append(_Column(f"{other.name}: T offset", "", "base"))
                g_cols.append(np.ones(tr.samples) if j == i else zero)
                f_cols.append(zero)
        return (
            names,
            np.asarray(g_cols).reshape(-1, tr.samples),
            np.asarray(f_cols).reshape(-1, tr.samples),
        )


@dataclass
class BalanceFit:
    """A variant fitted to the balances: its formula and its held-out blocks' errors."""

    kind: str
    channel: str
    formula: str
    #: Mean squared balance error (noise units) per held-out block, before and after.
    before: FloatArray
    after: FloatArray
    #: How well the balances' noise unit is known, as a share (``noise_resolution``).
    resolution: float = 0.1
    #: Per recording: the balances after the baseline's own terms and the term's fit.
    series: tuple[BalanceSeries, ...] = ()

    @property
    def name(self) -> str:
        """``kind in channel`` of the balances."""
        return f"{self.kind} in {self.channel} (balances)"


_ROUTES = {"u+F": {"weight", "tension"}, "u": {"u"}, "F": {"F"}}


def fit_balances(
    traces: Sequence[Trace],
    outputs: Sequence[Outputs],
    nominal: StandParams,
    values: dict[str, float],
) -> list[BalanceFit]:
    """Every variant of ``BALANCE_VARIANTS`` fitted to the balances (see the module).

    ``outputs``: the model's; its tension (noise-free) makes the strain and resonance
    terms: the recorded force's noise through a library of modes added noise to every
    held-out block, and a 56 Hz anchor mode that closed half the balances' error lost
    its test to the blocks it did not ring in.
    """
    balances = [
        _balances(tr, nominal, values, out) for tr, out in zip(traces, outputs, strict=True)
    ]
    library = _BalanceLibrary(traces, balances, nominal, values)

    def training(kind: str) -> tuple[list[_Column], FloatArray, FloatArray]:
        """Columns (terms × samples) and target over the training samples of every trace."""
        cols, target = [], []
        names: list[_Column] = []
        for i, (tr, b) in enumerate(zip(traces, balances, strict=True)):
            names, g_cols, f_cols = library.columns(kind, i)
            sg, sf = tr.train & b.use_g, tr.train & b.use_f
            cols.append(np.hstack([g_cols[:, sg] / b.noise_g, f_cols[:, sf] / b.noise_f]))
            target.append(np.concatenate([b.g[sg] / b.noise_g, b.f[sf] / b.noise_f]))
        return names, np.hstack(cols), np.concatenate(target)

    base_names, base_train, target = training("base")
    base_coef = stlsq(base_train.T, target, 0.0, np.ones(len(base_names), dtype=bool))
    before = _block_errors(traces, balances, library, "base", base_coef)
    fits = []
    for kind in dict.fromkeys(k for k, _ in BALANCE_VARIANTS):
        names, train, _ = training(kind)
        for variant, channel in BALANCE_VARIANTS:
            if variant != kind:
                continue
            rows = np.array([c.route in _ROUTES[channel] for c in names])
            stacked = np.vstack([train[rows], base_train])
            always = np.r_[np.zeros(int(rows.sum()), dtype=bool), np.ones(len(base_names), bool)]
            coef = stlsq(stacked.T, target, THRESHOLD_NOISE, always)
            mine = np.zeros(len(names))
            mine[rows] = coef[: int(rows.sum())]
            own_base = coef[int(rows.sum()) :]
            after = _block_errors(traces, balances, library, kind, mine, base_coef=own_base)
            formula = " + ".join(_text(c, w) for c, w in zip(names, mine, strict=True) if w != 0.0)
            series = tuple(_series(library, kind, i, mine, own_base) for i in range(len(traces)))
            fits.append(BalanceFit(kind, channel, formula or "0", before, after,
                                   noise_resolution(traces), series))  # fmt: skip
    return fits


def _series(
    library: _BalanceLibrary, kind: str, i: int, coef: FloatArray, base_coef: FloatArray
) -> BalanceSeries:
    """Trace ``i``'s balances less the baseline's own terms, and the kind's fit, N."""
    tr, b = library.traces[i], library.balances[i]
    _, g_cols, f_cols = library.columns(kind, i)
    _, bg, bf = library.columns("base", i)
    return BalanceSeries(
        tr.name, tr.rate_hz, tr.train, b.g - base_coef @ bg, coef @ g_cols, b.use_g,
        b.f - base_coef @ bf, coef @ f_cols, b.use_f,
    )  # fmt: skip


def noise_resolution(traces: Sequence[Trace]) -> float:
    """The relative standard error of the balances' noise unit, pooled over recordings.

    Each balance's noise is its spread over ``REST_S`` after the low-pass, about
    2·``LOWPASS_HZ``·duration independent samples: a spread from n of them is known to
    1/√(2n), and the recordings' units pool. 0.35 s of rest at 100 Hz: 8.5 % for one
    recording, 4.2 % for four.
    """
    n = 2.0 * LOWPASS_HZ * (REST_S[1] - REST_S[0])
    return float(1.0 / np.sqrt(2.0 * n) / np.sqrt(max(len(traces), 1)))


def _block_errors(
    traces: Sequence[Trace],
    balances: Sequence[_Balances],
    library: _BalanceLibrary,
    kind: str,
    coef: FloatArray,
    base_coef: FloatArray | None = None,
) -> FloatArray:
    """Mean squared balance error (noise units) of every held-out block after a fit."""
    errors = []
    for i, (tr, b) in enumerate(zip(traces, balances, strict=True)):
        _, g_cols, f_cols = library.columns(kind, i)
        g_fit = coef @ g_cols
        f_fit = coef @ f_cols
        if base_coef is not None:
            _, bg, bf = library.columns("base", i)
            g_fit = g_fit + base_coef @ bg
            f_fit = f_fit + base_coef @ bf
        rg = np.where(b.use_g, (b.g - g_fit) / b.noise_g, np.nan)
        rf = np.where(b.use_f, (b.f - f_fit) / b.noise_f, np.nan)
        for sel in held_out_blocks(tr):
            # The two balances pooled as a geometric mean (as ``heldout_excess`` pools
            # channels): each counts by how much a term improves it, not by its samples'
            # count. Pooled as one mean, the taut fibre's law (most samples) diluted an
            # oiled guide's drag on the sliding weight to a 4 % gain.
            parts = [r[sel][np.isfinite(r[sel])] for r in (rg, rf)]
            mse = [float(np.mean(p**2)) for p in parts if p.size]
            errors.append(float(np.exp(np.mean(np.log(np.maximum(mse, 1e-300))))) if mse else 0.0)
    return np.asarray(errors, dtype=np.float64)


_WHERE = {"weight": "force on the weight", "tension": "fibre tension", "u": "u reading",
          "F": "F reading"}  # fmt: skip


def _text(column: _Column, weight: float) -> str:
    value, unit = (weight * 1e3, "mm") if column.unit == "m" else (weight, column.unit)
    return f"{value:+.3g} {unit}·{column.name} [{_WHERE[column.route]}]"
