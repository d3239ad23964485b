"""``labstand diagnose --campaigns FILE``: every campaign of a manifest, in parallel on Dask."""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Any

from labstand.campaign_table import campaign_row, write_results
from labstand.campaigns import Campaign, diagnose_campaign, load_manifest
from labstand.distributed import (
    ClusterOptions,
    JobResult,
    Progress,
    open_client,
    run_jobs,
    say_failures,
)
from labstand.errors import ExitCode

LABEL = "labstand diagnose"


def run_campaigns(args: argparse.Namespace) -> int:
    """Diagnose the manifest's campaigns; print, and write ``--results``.

    Exit 0 when every campaign was diagnosed, 1 when any failed (its error is in its
    result; the others are reported all the same).
    """
    campaigns = load_manifest(args.campaigns)
    default_stand: Path | None = args.stand
    if default_stand is not None:
        campaigns = [
            c if c.stand is not None else dataclasses.replace(c, stand=default_stand.resolve())
            for c in campaigns
        ]
    options = ClusterOptions.from_args(args)
    progress = Progress(LABEL, len(campaigns), quiet=args.json)

    def tell(r: JobResult[dict[str, Any]]) -> str:
        if r.value is None:
            return f"{r.key}: FAILED: {r.error}"
        return f"{r.key}: {r.value['effect']} ({r.seconds:.0f} s on {r.worker})"

    keys = [c.name for c in campaigns]
    if len(campaigns) == 1 and not options.explicit:
        results = run_jobs(None, diagnose_campaign, campaigns, keys, progress, describe=tell)
    else:
        with open_client(options, progress.say) as (client, threads):
            results = run_jobs(client, diagnose_campaign, campaigns, keys, progress, threads, tell)
    out = [_result(c, r) for c, r in zip(campaigns, results, strict=True)]
    rows = [
        campaign_row(c.name, c.truth, r.value, r.seconds, r.worker, r.error)
        for c, r in zip(campaigns, results, strict=True)
    ]
    if args.results is not None:
        files = write_results(args.results, rows)
        progress.say(f"wrote {', '.join(str(f) for f in files)}")
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        _print_table(rows)
    return ExitCode.FAILURE if say_failures(LABEL, results) else ExitCode.OK


def _result(campaign: Campaign, r: JobResult[dict[str, Any]]) -> dict[str, Any]:
    """One campaign's JSON: the diagnosis (name, effect, ...) or its error."""
    where = {"seconds": r.seconds, "worker": r.worker}
    if r.value is not None:
        return {**r.value, **where}
    return {
        "name": campaign.name,
        "truth": campaign.truth,
        "recordings": [str(p) for p in campaign.recordings],
        "mass_kg": campaign.mass_kg,
        "effect": None,
        "error": r.error,
        **where,
    }


def _print_table(rows: list[dict[str, Any]]) -> None:
    width = max(len("campaign"), *(len(r["name"]) for r in rows))
    print(f"{'campaign':{width}s}  {'effect':26s} {'closure':>7s} {'F NRMSE before→after':>22s}"
          f" {'time':>6s}")  # fmt: skip
    for r in rows:
        if r["error"] is not None:
            print(f"{r['name']:{width}s}  FAILED: {r['error']}")
            continue
        gap = f"{r['nrmse_F_before']:.4f} → {r['nrmse_F_after']:.4f}"
        print(
            f"{r['name']:{width}s}  {r['answer']:26s} {r['gap_closure']:7.0%} {gap:>22s} "
            f"{r['seconds']:5.0f}s"
        )
