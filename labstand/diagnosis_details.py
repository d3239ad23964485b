"""The report below its first screen: the ranking, what remains, per recording, provenance."""

from __future__ import annotations

import html
from collections.abc import Mapping
from typing import Any

from labstand.diagnosis_charts import CLIP_CLOSURE
from labstand.diagnosis_html import FITTED_TO, NOT_COMPUTED, interval_text, number
from sim.identify import Diagnosis

__all__ = [
    "provenance_section",
    "ranking_section",
    "recording_section",
    "remainder_section",
    "where_tables",
]


def ranking_section(result: Diagnosis) -> str:
    """Every candidate alone on the baseline: the chart and its numbers."""
    rows = []
    for r in result.ranking:
        clipped = r.score is not None and r.score < CLIP_CLOSURE
        bound = f" — at its bound: {html.escape(', '.join(r.at_bound))}" if r.at_bound else ""
        params = ", ".join(f"{html.escape(k)} {number(v)}" for k, v in r.params.items())
        rows.append(
            f"<tr><td>{html.escape(r.effect)}</td>"
            f"<td>{number(r.score, 3)}{' (clipped in the chart)' if clipped else ''}</td>"
            f"<td>{number(r.heldout_error)}</td><td>{number(r.p_family, 2)}</td>"
            f"<td>{number(r.screening, 3)}</td><td>{params}{bound}</td></tr>"
        )
    return f"""<h2 id="ranking">Each candidate alone</h2>
<p>Each of the candidate effects refitted alone on top of the baseline and judged on the
held-out cycles: the share of the baseline's gap above the noise it closes (held-out
NRMSE of the baseline: {number(result.heldout_error_before)}).</p>
<img src="ranking.png" alt="ranking of the candidate effects">
<table><tr><th>effect</th><th>held-out gap closure</th><th>held-out NRMSE</th>
<th>family p</th><th>screening</th><th>fitted parameters</th></tr>{"".join(rows)}</table>"""


def remainder_section(result: Diagnosis, plotted: bool) -> str:
    """What remains after the named effects: the test, and the signatures that pass."""
    from sim.identify.remainder import VERDICT_WORDS

    rem = result.remainder
    if rem is None:
        return f'<h2 id="remainder">What remains</h2><p>{NOT_COMPUTED}.</p>'
    state = html.escape(rem.state)
    rows = "".join(
        f"<tr><td>{html.escape(s.kind)}</td><td>{html.escape(s.channel)}</td>"
        f"<td>{html.escape(FITTED_TO.get(s.source, s.source))}</td>"
        f"<td>{s.closes:.0%}</td><td>{s.p_family:.2g}</td><td>{'yes' if s.passes else 'no'}</td>"
        f"<td><code>{html.escape(s.formula)}</code></td></tr>"
        for s in rem.signature
    )
    plot = (
        '<img src="remainder.png" alt="the remainder against its best signature">'
        if plotted
        else "<p>No signature of the remainder passes: nothing to plot.</p>"
    )
    return f"""<h2 id="remainder">What remains</h2>
<p><b>{html.escape(VERDICT_WORDS.get(result.verdict, result.verdict))}</b>.
The remainder is {state} (family p = {rem.p_value:.2g} over the signature kinds); its
held-out error is {rem.excess:.2f} × the noise, {rem.share_of_gap:.0%} of the baseline's gap.</p>
<table><tr><th>kind</th><th>acts in</th><th>fitted to</th>
<th>closes (of the remainder; of a balance's error)</th><th>p (family)</th>
<th>evidence</th><th>fitted terms</th></tr>{rows}</table>
{plot}"""


def recording_section(result: Diagnosis, plotted: bool) -> str:
    """The parameters fitted per recording, and whether they agree across recordings."""
    fits = result.per_recording
    if not fits:
        return (
            '<h2 id="per-recording">Per recording</h2>'
            f"<p>Parameters fitted per recording: {NOT_COMPUTED} in this diagnosis.</p>"
        )
    names = sorted({n for fit in fits.values() for n in fit.get("params", {})})
    head = "".join(f"<th><code>{html.escape(n)}</code></th>" for n in names)
    rows = []
    for rec, fit in fits.items():
        cells = "".join(
            f"<td>{number(fit.get('params', {}).get(n))} "
            f"{interval_text(fit.get('intervals', {}).get(n), 3)}</td>"
            for n in names
        )
        rows.append(
            f"<tr><td>{html.escape(rec)}</td><td>{number(fit.get('drive_rate_hz'))}</td>"
            f"<td>{number(_mm(fit.get('stroke_m', fit.get('amplitude_m'))))}</td>"
            f"<td>{number(fit.get('mass_kg'))}</td>{cells}</tr>"
        )
    tests = [(n, t, "") for n, t in result.consistency.items()]
    if result.effects:  # the baseline alone too: what the named effects took out
        tests += [(n, t, " (baseline alone)") for n, t in result.baseline_consistency.items()]
    agree = "".join(
        f"<tr><td><code>{html.escape(n)}</code>{alone}</td>"
        f"<td>{number(t.get('p_value'), 2)}</td>"
        f"<td>{html.escape(str(t.get('trend') or 'none found'))}</td>"
        f"<td>{html.escape(str(t.get('points_to') or ''))}</td></tr>"
        for n, t, alone in tests
    )
    consistency = (
        "<table><tr><th>parameter</th><th>p (they agree)</th><th>trend</th>"
        f"<th>points to</th></tr>{agree}</table>"
        if agree
        else f"<p>Agreement across recordings: {NOT_COMPUTED}.</p>"
    )
    rates = "".join(
        f"<li>{html.escape(label)}: {html.escape(str(r['trend']))}"
        f"{html.escape(': ' + r['points_to']) if r.get('points_to') else ''}</li>"
        for key, label in (("baseline_alone", "baseline alone"), ("final", "final model"))
        if (r := result.dynamic_stiffness.get(key))
    )
    dynamic = (
        "<p>The fibre's stiffness at each rate it is strained at, read off its law in the "
        "recordings (F = k·e + c·ė and relaxation branches of 10–300 ms, fitted to the "
        "training cycles, judged on the held-out ones against the model's own reading; the "
        f"line in the stiffness panel):</p><ul>{rates}</ul>"
        if rates
        else ""
    )
    plot = (
        '<img src="per_recording.png" alt="parameters per recording against the drive rate">'
        if plotted
        else ""
    )
    return f"""<h2 id="per-recording">Per recording</h2>
<p>The parameters fitted to each recording alone, with their 95 % intervals, against the
recording's drive rate (its motion's rms frequency); a small p says they differ between
recordings. Where effects are named, the baseline alone is fitted per recording too: the
stiffness, damping and friction a hand-tuned model would need for each test, and whether
the named effects explain why they differ.</p>
{plot}
{dynamic}
<table><tr><th>recording</th><th>drive rate [Hz]</th><th>stroke [mm]</th>
<th>mass [kg]</th>{head}</tr>{"".join(rows)}</table>
{consistency}"""


def _mm(metres: object) -> float | None:
    return float(metres) * 1e3 if isinstance(metres, int | float) else None


def where_tables(result: Diagnosis) -> str:
    """The where chart's numbers, folded away (the chart shows them)."""
    where = result.where
    rows = []
    for label, shares in (("phase", where.phase), ("regime", where.regime),
                          ("band", where.band)):  # fmt: skip
        for channel, split in shares.items():
            cells = ", ".join(f"{html.escape(k)} {v:.1%}" for k, v in split.items())
            rows.append(f"<tr><td>{label}</td><td>{html.escape(channel)}</td><td>{cells}</td></tr>")
    channels = ", ".join(f"{html.escape(k)} {v:.1%}" for k, v in where.channel.items())
    return (
        "<details><summary>the shares as numbers</summary>"
        f"<p>By channel: {channels}.</p><table><tr><th>by</th><th>channel</th>"
        f"<th>shares within the channel</th></tr>{''.join(rows)}</table></details>"
    )


def provenance_section(provenance: Mapping[str, Any] | None, result: Diagnosis) -> str:
    """What the diagnosis read and what wrote it (the same dict as result.json's)."""
    if not provenance:
        return f'<h2 id="provenance">Provenance</h2><p>{NOT_COMPUTED}.</p>'
    rows = "".join(
        f"<tr><td>{html.escape(str(r['name']))}<br><small>{html.escape(str(r['path']))}"
        f'</small></td><td><code class="hash">{html.escape(str(r["sha256"]))}</code></td>'
        f"<td>{r['mass_kg']:g} kg<br><small>{html.escape(str(r['mass_source']))}</small></td>"
        f"<td>{_signal(r.get('signal'))}</td>"
        f"<td>{html.escape(str(r.get('backend') or '—'))}{_simulated(r)}<br><small>"
        f"{html.escape(str(r.get('start_time_utc') or ''))}</small></td></tr>"
        for r in provenance.get("recordings", [])
    )
    stand = provenance.get("stand", {})
    stand_hash = (
        f' (sha256 <code class="hash">{html.escape(str(stand["sha256"]))}</code>)'
        if stand.get("sha256")
        else ""
    )
    return f"""<h2 id="provenance">Provenance</h2>
<table><tr><th>recording</th><th>sha256</th><th>mass</th><th>drive signal</th>
<th>recorded by</th></tr>{rows}</table>
<p>Stand: {html.escape(str(stand.get("label")))}{stand_hash}, parameter set
<code>{html.escape(str(stand.get("parameter_set")))}</code>.
Written by labstand {html.escape(str(provenance.get("labstand_version")))} on
{html.escape(str(provenance.get("created_utc")))}{_cost(result)}. The same record is
<code>provenance</code> in
<a href="result.json">result.json</a>.</p>"""


def _cost(result: Diagnosis) -> str:
    total = result.timings_s.get("total")
    if total is None:
        return ""
    return f"; {result.simulations} simulations in {total:.3g} s"


def _simulated(recording: Mapping[str, Any]) -> str:
    """The effects a simulated recording was made with (the truth a check compares to)."""
    effects = recording.get("simulated_effects") or []
    named = [
        f"{html.escape(str(e.get('name')))} ("
        + ", ".join(f"{html.escape(str(k))} {number(v)}" for k, v in e.get("params", {}).items())
        + ")"
        for e in effects
    ]
    return f", with {'; '.join(named)}" if named else ""


def _signal(signal: Mapping[str, Any] | None) -> str:
    if not signal:
        return '<span class="muted">not stored in the recording</span>'
    parts = [html.escape(str(signal.get("shape", "?")))]
    if "situation" in signal:  # the paper's numbering
        parts[0] = f"situation {html.escape(str(signal['situation']))}: {parts[0]}"
    for key, unit in (("amplitude_mm", "mm"), ("frequency_hz", "Hz"), ("cycles", "cycles")):
        if key in signal:
            parts.append(f"{number(signal[key])} {unit}")
    return ", ".join(parts)
