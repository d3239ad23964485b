"""The diagnosis report as a reader meets it: opened in headless Chromium, offline.

The diagnosis is built by hand around a simulated campaign (a real ``diagnose`` takes
a minute; ``tests/identify`` runs those), with every field the page reads filled in,
a parameter at its bound and a candidate whose closure the chart must clip. Chromium
resolves no host names here, so anything the page fetched from the network would fail.
"""

from __future__ import annotations

import hashlib
import html
import json
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from labstand.diagnosis_report import write_report
from labstand.provenance import BUILT_IN_STAND, RecordingSource, build_provenance
from sim.checks.check import SMALL_CAMPAIGN, make_campaign
from sim.config import StandConfig
from sim.effects import EFFECTS
from sim.identify import Diagnosis, Trace
from sim.identify.heldout import Outputs, channel_gap, heldout_error, noise_floor
from sim.identify.remainder import VERDICT_WORDS
from sim.identify.report import AcceptedEffect, RankedEffect
from sim.identify.where import SimStates, where_the_gap_lies

#: The first screen of a laptop: the four answers must start within it.
WINDOW = (1280, 900)
#: Appended to a copy of the page, beside it (same origin as its images): what the
#: browser loaded and where it laid the four answers out, written into the DOM.
PROBE = """<script>
window.addEventListener("load", () => {
  const box = (el) => { const r = el.getBoundingClientRect();
    return {top: r.top + scrollY, bottom: r.bottom + scrollY}; };
  const out = {
    images: Array.from(document.images,
      (img) => ({src: img.getAttribute("src"), width: img.naturalWidth})),
    sections: Object.fromEntries(["which", "how-sure", "how-far", "where"]
      .map((id) => [id, box(document.getElementById(id))])),
    viewport: innerHeight,
  };
  const pre = document.createElement("pre");
  pre.id = "probe";
  pre.textContent = JSON.stringify(out);
  document.body.append(pre);
});
</script></body>"""


def _campaign(stand: StandConfig, tmp_path: Path) -> tuple[list[Trace], Diagnosis, dict[str, Any]]:
    traces, truth, truth_params = make_campaign(
        stand, "fibre_viscoelastic", 8.131, np.random.default_rng(0), SMALL_CAMPAIGN
    )
    # The truth's own parameters (not its baseline multipliers).
    own = {p.name for p in EFFECTS["fibre_viscoelastic"].params}
    params = {k: v for k, v in truth_params.items() if k in own}
    # The baseline misses the force by a few newtons while the drive moves; the final
    # model is the truth.
    before = [
        Outputs(o.u_m, o.force_n + 4.0 * np.sin(2 * np.pi * 7 * np.arange(tr.samples) / tr.rate_hz))
        for tr, o in zip(traces, truth, strict=True)
    ]
    states = [
        SimStates(o.u_m, o.force_n, np.gradient(o.u_m, 1 / tr.rate_hz))
        for tr, o in zip(traces, before, strict=True)
    ]
    named = AcceptedEffect(
        "fibre_viscoelastic", 0.97, 0.0012, dict(params), at_bound=[],
        intervals={k: (0.8 * v, 1.25 * v) for k, v in params.items()},
    )  # fmt: skip
    ranking = [
        RankedEffect("fibre_viscoelastic", 0.6, 0.97, p_family=0.0012, params=dict(params)),
        RankedEffect("channel_time_skew", 0.2, -0.3, p_family=1.0),
        RankedEffect("fibre_pulley_jump", 0.01, -3.5, p_family=1.0),  # drawn clipped
        RankedEffect("stick_slip_friction", 0.0),  # not refitted
    ]
    result = Diagnosis(
        effects=[named], ranking=ranking, where=where_the_gap_lies(traces, states),
        gap_before=channel_gap(traces, before), gap_after=channel_gap(traces, truth),
        baseline={"stiffness_scale": 1.1, "damping_scale": 4.0, "friction_scale": 0.4},
        heldout_error_before=heldout_error(traces, before),
        heldout_error_after=heldout_error(traces, truth), noise_floor=noise_floor(traces),
        gap_closure=0.97, confidence=1.0, outputs_before=before, outputs_after=list(truth),
        verdict="explained",
        # damping_scale's interval reaches its range's end (4): marked at its bound
        baseline_intervals={"stiffness_scale": (1.05, 1.15), "damping_scale": (3.2, 4.0),
                            "friction_scale": (0.3, 0.5)},
        gap_closure_interval=(0.93, 0.99), interval_method="block bootstrap (test)",
        per_recording={
            tr.name: {"params": {"stiffness_scale": 1.0 + 0.1 * k},
                      "intervals": {"stiffness_scale": (0.95 + 0.1 * k, 1.05 + 0.1 * k)},
                      "drive_rate_hz": spec.frequency_hz, "amplitude_m": spec.amplitude_m,
                      "mass_kg": 8.131}
            for k, (tr, (_, spec)) in enumerate(zip(traces, SMALL_CAMPAIGN, strict=True))
        },
        consistency={"stiffness_scale": {"p_value": 0.004, "trend": "grows with the rate"}},
        dynamic_stiffness={"baseline_alone": {
            "frequencies_hz": [0.5, 2.0, 12.0], "stiffness_scale": [1.0, 1.1, 1.3],
            "intervals": [[0.98, 1.02], [1.08, 1.12], [1.27, 1.33]],
            "model_stiffness_scale": [1.2, 1.2, 1.2], "rises_with_rate": True,
            "trend": "rises with the strain rate: x1 at 0.5 Hz to x1.3 at 12 Hz",
            "points_to": "a relaxation branch",
        }},
    )  # fmt: skip
    sources = []
    for tr, (_, spec) in zip(traces, SMALL_CAMPAIGN, strict=True):
        path = tmp_path / f"{tr.name}.csv"
        t = np.arange(tr.samples) / tr.rate_hz
        np.savetxt(path, np.column_stack([t, tr.x_m * 1e3, tr.u_m * 1e3, tr.force_n]),
                   delimiter=",", header="t_s,x_mm,u_mm,F_N", comments="")  # fmt: skip
        meta = {"backend": "sim", "signal": spec.to_dict()}
        sources.append(RecordingSource(path, tr.name, 8.131, "--mass-kg", meta))
    return traces, result, build_provenance(sources, None, "final")


def _open_in_chromium(page: Path, tmp_path: Path) -> dict[str, Any]:
    chromium = shutil.which("chromium")
    if chromium is None:
        pytest.fail("chromium is not installed (make system-tools installs it)")
    probe = page.with_name("probe.html")
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", PROBE))
    dom = subprocess.run(
        [chromium, "--headless", "--disable-gpu", "--no-sandbox",
         f"--user-data-dir={tmp_path / 'chromium'}", f"--window-size={WINDOW[0]},{WINDOW[1]}",
         "--virtual-time-budget=5000", "--host-resolver-rules=MAP * ~NOTFOUND",
         "--dump-dom", probe.as_uri()],
        capture_output=True, text=True, timeout=60, check=True,
    ).stdout  # fmt: skip
    found = re.search(r'<pre id="probe">(.*?)</pre>', dom, re.S)
    assert found, "the page's load event never ran"
    return dict(json.loads(found.group(1).replace("&quot;", '"').replace("&amp;", "&")))


def _section(page: str, name: str) -> str:
    found = re.search(rf'<section id="{name}">(.*?)</section>', page, re.S)
    assert found, f"no {name} section"
    return found.group(1)


def test_the_first_screen_answers_which_how_sure_how_far_and_where_offline(
    stand: StandConfig, tmp_path: Path
) -> None:
    traces, result, provenance = _campaign(stand, tmp_path)
    index = write_report(tmp_path / "report", traces, result, provenance)
    seen = _open_in_chromium(index, tmp_path)

    # Every image loaded from the files beside the page; nothing refers off the machine.
    assert {i["src"] for i in seen["images"]} >= {"where.png", "ranking.png", "overlay.png",
                                                 "per_recording.png", "residual.png"}  # fmt: skip
    assert all(i["width"] > 0 for i in seen["images"]), seen["images"]
    page = index.read_text(encoding="utf-8")
    assert not re.search(r'(src|href)="(https?:)?//', page)
    # The four answers start on the first screen, in reading order.
    tops = [seen["sections"][s]["top"] for s in ("which", "how-sure", "how-far", "where")]
    assert max(tops) < seen["viewport"], seen

    which = _section(page, "which")
    assert VERDICT_WORDS["explained"].split(": ")[1] in which
    assert "<b>fibre_viscoelastic</b> (family p = 0.0012)" in which
    sure = _section(page, "how-sure")
    for name, (low, high) in result.effects[0].intervals.items():
        assert f"<code>{name}</code>" in sure and f"[{low:.4g}, {high:.4g}]" in sure
    damping = re.search(r"<code>damping_scale</code>.*?</tr>", sure, re.S)
    stiffness = re.search(r"<code>stiffness_scale</code>.*?</tr>", sure, re.S)
    assert damping and "at its bound" in damping.group(0)
    assert stiffness and "at its bound" not in stiffness.group(0)
    assert "[93%, 99%]" in sure and "block bootstrap (test)" in sure
    far = _section(page, "how-far")
    for channel in ("u", "F"):
        b, a = result.gap_before[channel]["nrmse"], result.gap_after[channel]["nrmse"]
        assert f"{b:.4g}" in far and f"{a:.4g}" in far and f"{(a - b) / b:+.0%}" in far
    assert 'src="where.png"' in _section(page, "where")

    # The fibre's law read against the strain rate: its trend beside the per-recording fits.
    assert (
        "baseline alone: rises with the strain rate: x1 at 0.5 Hz to x1.3 at 12 Hz: a "
        "relaxation branch" in page
    )

    # The ranking's clipped candidate says so; provenance names each file by its hash.
    assert "-3.5 (clipped in the chart)" in page
    for source in provenance["recordings"]:
        digest = hashlib.sha256(Path(source["path"]).read_bytes()).hexdigest()
        assert source["sha256"] == digest and digest in page
    assert "8.131 kg" in page and html.escape(BUILT_IN_STAND) in page
    assert "trapezoidal, 25 mm, 2 Hz, 4 cycles" in page
    stored = json.loads((index.parent / "result.json").read_text())
    assert stored["provenance"] == provenance


def test_a_diagnosis_without_intervals_says_they_were_not_computed(
    stand: StandConfig, tmp_path: Path
) -> None:
    traces, result, _ = _campaign(stand, tmp_path)
    result.effects[0].intervals = {}
    result.baseline_intervals, result.gap_closure_interval = {}, None
    result.gap_intervals, result.interval_method = {}, ""
    result.per_recording, result.consistency = {}, {}
    index = write_report(tmp_path / "report", traces, result)
    page = index.read_text(encoding="utf-8")
    sure = _section(page, "how-sure")
    # every fitted number, each with "not computed" where its interval would be
    assert sure.count("not computed") == len(result.effects[0].params) + 3 + 1 + 1
    assert "Parameters fitted per recording: not computed" in page
    assert not (index.parent / "per_recording.png").exists()
    assert json.loads((index.parent / "result.json").read_text())["provenance"] is None


def test_with_nothing_named_the_first_screen_says_so_and_names_the_best_try(
    stand: StandConfig, tmp_path: Path
) -> None:
    traces, result, provenance = _campaign(stand, tmp_path)
    result.effects, result.verdict = [], "baseline_adequate"
    result.ranking[0].score, result.ranking[0].p_family = 0.05, 0.4
    page = write_report(tmp_path / "report", traces, result, provenance).read_text()
    which = _section(page, "which")
    assert "<b>Baseline adequate</b>: no systematic gap beyond the noise; no effect named." in which
    assert (
        "fibre_viscoelastic, closes 5% of the held-out gap at family p = 0.4: not enough" in which
    )
    sure = _section(page, "how-sure")
    assert "fibre_viscoelastic" not in sure and "<code>stiffness_scale</code>" in sure
