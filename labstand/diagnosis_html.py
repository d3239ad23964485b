"""The report's first screen: which effect, how sure, how far the gap shrinks, and where.

Each part is an HTML fragment built from the typed ``Diagnosis``; numbers the
diagnosis did not compute (intervals, per-recording fits) say so instead of vanishing.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from sim.identify import Diagnosis

if TYPE_CHECKING:
    from sim.identify.fitting import FreeParam

__all__ = ["first_screen", "interval_text", "number"]

#: The channels in words (the page's reader may not know u and F).
CHANNEL_WORDS = {"u": "u, weight displacement", "F": "F, fibre force"}
NOT_COMPUTED = "not computed"
#: What a remainder signature was fitted to, in words (``Signature.source``).
FITTED_TO = {"outputs": "the model's outputs", "balances": "the balances"}


def number(value: object, digits: int = 4) -> str:
    """A number as the page prints it: ``digits`` significant, '—' for None or NaN."""
    if value is None:
        return "—"
    if isinstance(value, bool) or not isinstance(value, int | float):
        return html.escape(str(value))
    if not math.isfinite(value):
        return "—"
    return f"{value:.{digits}g}"


def interval_text(interval: Iterable[float] | None, digits: int = 4) -> str:
    """``[low, high]``, or 'not computed'."""
    if interval is None:
        return f'<span class="muted">{NOT_COMPUTED}</span>'
    low, high = interval
    return f'<span class="iv">[{number(low, digits)}, {number(high, digits)}]</span>'


def first_screen(result: Diagnosis, provenance: Mapping[str, Any] | None) -> str:
    """The title, a line of provenance, and the four answers in a grid."""
    named = " + ".join(e.effect for e in result.effects) or "none"
    return f"""<header>
<h1>Diagnosis: <code>{html.escape(named)}</code></h1>
<p class="muted">{_source_line(provenance)}</p></header>
<div class="grid">
<section id="which"><h2>Which</h2>{_which(result)}</section>
<section id="how-sure"><h2>How sure</h2>{_how_sure(result)}</section>
<section id="how-far"><h2>How far</h2>{_how_far(result)}</section>
<section id="where"><h2>Where</h2>{_where(result)}</section>
</div>"""


def _source_line(provenance: Mapping[str, Any] | None) -> str:
    if not provenance:
        return 'Provenance: <span class="muted">not recorded</span>'
    recordings = provenance.get("recordings", [])
    masses = sorted({f"{r['mass_kg']:g} kg ({r['mass_source']})" for r in recordings})
    names = ", ".join(html.escape(str(r["name"])) for r in recordings)
    stand = provenance.get("stand", {})
    return (
        f"{len(recordings)} recording{'s' if len(recordings) != 1 else ''} ({names}) · "
        f"mass {html.escape('; '.join(masses))} · stand {html.escape(str(stand.get('label')))} · "
        f"labstand {html.escape(str(provenance.get('labstand_version')))} · "
        f"{html.escape(_date(provenance.get('created_utc')))} · "
        '<a href="#provenance">provenance</a>'
    )


def _date(iso: object) -> str:
    """An ISO 8601 time as a person reads it: '2026-11-27 02:50 UTC'."""
    from datetime import UTC, datetime

    try:
        return datetime.fromisoformat(str(iso)).astimezone(UTC).strftime("%Y-%m-%d %H:%M UTC")
    except ValueError:
        return str(iso)


def _which(result: Diagnosis) -> str:
    from sim.identify.remainder import VERDICT_WORDS

    words = VERDICT_WORDS.get(result.verdict, result.verdict)
    head, _, rest = words.partition(": ")
    named = [
        f"<b>{html.escape(e.effect)}</b> (family p = {number(e.p_value, 2)})"
        for e in result.effects
    ]
    sentence = f"<b>{html.escape(head.capitalize())}</b>: {html.escape(rest)}"
    sentence += f" — {' + '.join(named)}." if named else "; no effect named."
    parts = [f'<p class="verdict">{sentence}</p><ul>']
    for e in result.effects:
        line = f"<b>{html.escape(e.effect)}</b> closes {e.closure:.0%} of the held-out gap"
        if e.indistinguishable_from:
            line += "; the recordings cannot tell it from " + html.escape(
                ", ".join(e.indistinguishable_from)
            )
        parts.append(f"<li>{line}.</li>")
    if not result.effects:
        parts.append(f"<li>{_best_unnamed(result)}</li>")
    for effect, kind in result.displaced.items():
        parts.append(
            f"<li>{html.escape(effect)} passed its test but did no better than a "
            f"{html.escape(kind)} term: not named.</li>"
        )
    rem = result.remainder
    if rem is not None:
        state = html.escape(rem.state)
        passing = [s for s in rem.signature if s.passes]
        like = (
            f"; it behaves like a {html.escape(passing[0].kind)} term in "
            f"{html.escape(passing[0].channel)} (fitted to "
            f"{html.escape(FITTED_TO.get(passing[0].source, passing[0].source))})"
            if passing
            else ""
        )
        parts.append(
            f"<li>What remains is {state} (family p = {number(rem.p_value, 2)}){like}: "
            f'<a href="#remainder">details</a>.</li>'
        )
    parts.append(f"</ul><p class=\"muted\">Family p: the candidates' joint test on held-out "
                 f"cycles; an effect is named at p ≤ α = {result.alpha:g}.</p>")  # fmt: skip
    return "".join(parts)


def _best_unnamed(result: Diagnosis) -> str:
    tried = [r for r in result.ranking if r.score is not None]
    if not tried:
        return "No candidate was refitted."
    best = tried[0]
    closes = f"closes {best.score:.0%}" if best.score and best.score > 0 else "closes none"
    weak = best.p_family is None or best.p_family > result.alpha
    return (
        f"The best candidate, {html.escape(best.effect)}, {closes} of the held-out gap at "
        f"family p = {number(best.p_family, 2)}{': not enough to name it' if weak else ''}."
    )


def _how_sure(result: Diagnosis) -> str:
    from sim.identify.fitting import BASELINE_PARAMS

    rows = []
    for e in result.effects:
        rows.append(f'<tr><th colspan="3">{html.escape(e.effect)}</th></tr>')
        free = _ranges(e.effect)
        for name, value in e.params.items():
            interval = e.intervals.get(name)
            reaches = name in e.at_bound or (
                interval is not None
                and name in free
                and any(_reaches(free[name], v) for v in interval)
            )
            rows.append(_param_row(name, value, interval, reaches))
    rows.append('<tr><th colspan="3">baseline (of the final model)</th></tr>')
    baseline_bounds = {name: (low, high) for name, low, high, _ in BASELINE_PARAMS}
    for name, value in result.baseline.items():
        interval = result.baseline_intervals.get(name)
        low, high = baseline_bounds.get(name, (-math.inf, math.inf))
        ends = [value, *(interval or ())]
        reaches = any(math.isclose(v, b, rel_tol=2e-3, abs_tol=1e-9) for v in ends
                      for b in (low, high))  # fmt: skip
        rows.append(_param_row(name, value, interval, reaches))
    closure = result.gap_closure_interval
    rows.append(
        '<tr><th colspan="3">the named effects together</th></tr><tr><td>held-out gap closure</td>'
        f"<td>{result.gap_closure:.0%}</td><td>{_percent_interval(closure)}</td></tr>"
    )
    method = (
        f"95 % intervals: {html.escape(result.interval_method)}."
        if result.interval_method
        else "95 % intervals: not computed in this diagnosis (best fits only)."
    )
    return (
        "<table><tr><th>parameter</th><th>fitted</th><th>95 % interval</th></tr>"
        f'{"".join(rows)}</table><p class="muted">{method} '
        '<span class="bound">at its bound</span>: the fit or its interval reaches the end of '
        "the parameter's physical range — the effect may be larger, or of another form.</p>"
    )


def _ranges(effect: str) -> dict[str, FreeParam]:
    """An effect's fitted parameters with their ranges (none for a name not in the catalogue)."""
    from sim.identify.fitting import Candidate

    try:
        params = Candidate.build(effect).params
    except KeyError:
        return {}
    prefix = f"{effect}."
    return {p.name[len(prefix) :]: p for p in params if p.name.startswith(prefix)}


def _reaches(free: FreeParam, value: float) -> bool:
    """Whether an interval's end lies on (or past) the end of a parameter's range."""
    if not math.isfinite(value) or value <= free.low or value >= free.high:
        return True
    return free.at_bound(value)


def _param_row(
    name: str, value: float, interval: tuple[float, float] | None, at_bound: bool
) -> str:
    mark = ' <span class="bound">at its bound</span>' if at_bound else ""
    return (
        f"<tr><td><code>{html.escape(name)}</code></td>"
        f"<td>{number(value)}</td><td>{interval_text(interval)}{mark}</td></tr>"
    )


def _percent_interval(interval: tuple[float, float] | None) -> str:
    if interval is None:
        return f'<span class="muted">{NOT_COMPUTED}</span>'
    return f'<span class="iv">[{interval[0]:.0%}, {interval[1]:.0%}]</span>'


def _how_far(result: Diagnosis) -> str:
    before_iv = result.gap_intervals.get("before", {})
    after_iv = result.gap_intervals.get("after", {})
    rows = []
    for channel in result.gap_before:
        b, a = result.gap_before[channel]["nrmse"], result.gap_after[channel]["nrmse"]
        change = (a - b) / b if b > 0 else math.nan
        rows.append(
            f"<tr><td>{html.escape(CHANNEL_WORDS.get(channel, channel))}</td>"
            f"<td>{number(b)}{_small_interval(before_iv.get(channel))}</td>"
            f"<td>{number(a)}{_small_interval(after_iv.get(channel))}</td>"
            f'<td class="num">{_change(change)}</td>'
            f"<td>{_r(result.gap_before[channel])}<br>→ {_r(result.gap_after[channel])}</td></tr>"
        )
    b, a = result.heldout_error_before, result.heldout_error_after
    overall = (a - b) / b if b > 0 else math.nan
    rows.append(
        f'<tr class="total"><td>all channels (RMS)</td><td>{number(b)}</td>'
        f'<td>{number(a)}</td><td class="num">{_change(overall)}</td><td></td></tr>'
    )
    return (
        "<table><tr><th>channel</th><th>NRMSE before</th><th>after</th><th>change</th>"
        f"<th>R before → after</th></tr>{''.join(rows)}</table>"
        '<p class="muted">Held-out cycles only (never fitted): the fitted baseline before, '
        f"with the named effects after. Sensor noise alone would leave {number(result.noise_floor)}"
        f" (all channels).</p>"
    )


def _small_interval(interval: tuple[float, float] | None) -> str:
    if interval is None:
        return ""
    return f'<br><span class="muted">{interval_text(interval, 3)}</span>'


def _change(share: float) -> str:
    return "—" if not math.isfinite(share) else f"{share:+.0%}"


def _r(gap: Mapping[str, float]) -> str:
    from labstand.plots import r_text

    return r_text(gap["R"]) if "R" in gap else "—"


def _where(result: Diagnosis) -> str:
    where = result.where
    if not where.channel or not sum(where.channel.values()) > 0:
        return "<p>No residual to place.</p>"
    channel = max(where.channel, key=lambda c: where.channel[c])
    parts = []
    for label, shares in (("phase", where.phase), ("regime", where.regime),
                          ("band", where.band)):  # fmt: skip
        top = max(shares[channel], key=lambda k: shares[channel][k])
        parts.append(f"{label} <b>{html.escape(top)}</b> ({shares[channel][top]:.0%})")
    return (
        f"<p>Mostly in <b>{html.escape(CHANNEL_WORDS.get(channel, channel))}</b> "
        f"({where.channel[channel]:.0%} of the fitted baseline's squared residual); "
        f"there: {', '.join(parts)}.</p>"
        '<img src="where.png" alt="where the gap lies: shares by channel, phase, regime and '
        'band">'
    )
