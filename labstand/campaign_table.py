"""Campaign results as data: one row per campaign, and the confusion matrix.

``--results DIR`` writes ``campaigns.parquet`` (``campaigns.csv`` without pyarrow) and
``confusion.csv`` (rows: truth, columns: answer; campaigns with a known truth only), for
a user to open with ``pandas.read_parquet`` / ``read_csv``.
"""

from __future__ import annotations

import importlib.util
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from labstand.errors import CommandError

COLUMNS = [
    "name", "answer", "truth", "effects", "closures", "gap_closure",
    "nrmse_u_before", "nrmse_F_before", "nrmse_u_after", "nrmse_F_after",
    "heldout_error_before", "heldout_error_after", "seconds", "worker", "error",
]  # fmt: skip


def campaign_row(
    name: str,
    truth: str | None,
    diagnosis: Mapping[str, Any] | None,
    seconds: float,
    worker: str,
    error: str | None = None,
) -> dict[str, Any]:
    """A campaign's row from its diagnosis JSON (``Diagnosis.to_dict``), or its error."""
    row: dict[str, Any] = dict.fromkeys(COLUMNS)
    row.update(name=name, truth=truth, seconds=seconds, worker=worker, error=error)
    if diagnosis is None:
        return row
    effects = diagnosis["effects"]
    before, after = diagnosis["gap_before"], diagnosis["gap_after"]
    row.update(
        answer=diagnosis["effect"],
        effects=";".join(e["effect"] for e in effects),
        closures=json.dumps({e["effect"]: e["closure"] for e in effects}),
        gap_closure=diagnosis["gap_closure"],
        nrmse_u_before=before["u"]["nrmse"],
        nrmse_F_before=before["F"]["nrmse"],
        nrmse_u_after=after["u"]["nrmse"],
        nrmse_F_after=after["F"]["nrmse"],
        heldout_error_before=diagnosis["heldout_error_before"],
        heldout_error_after=diagnosis["heldout_error_after"],
    )
    return row


def confusion(rows: Sequence[Mapping[str, Any]], labels: Sequence[str] = ()) -> pd.DataFrame:
    """Counts of (truth, answer) over the rows with both; ``labels`` first, then any other."""
    known = [r for r in rows if r["truth"] is not None and r["answer"] is not None]
    seen = list(labels)
    for x in (label for r in known for label in (r["truth"], r["answer"])):
        if x not in seen:
            seen.append(x)
    counts = {(t, a): 0 for t in seen for a in seen}
    for r in known:
        counts[r["truth"], r["answer"]] += 1
    return pd.DataFrame(
        [[counts[t, a] for a in seen] for t in seen],
        index=pd.Index(seen, name="truth"),
        columns=pd.Index(seen, name="answer"),
    )


def write_results(
    folder: Path, rows: Sequence[Mapping[str, Any]], labels: Sequence[str] = ()
) -> list[Path]:
    """Write the table and the confusion matrix into ``folder``; returns the files."""
    try:
        folder.mkdir(exist_ok=True)  # its parent was checked before the work
        frame = pd.DataFrame(list(rows), columns=COLUMNS)
        if importlib.util.find_spec("pyarrow") is not None:
            table = folder / "campaigns.parquet"
            frame.to_parquet(table, index=False)
        else:
            table = folder / "campaigns.csv"
            frame.to_csv(table, index=False)
        matrix = folder / "confusion.csv"
        confusion(rows, labels).to_csv(matrix)
    except OSError as err:
        raise CommandError(f"{folder}: cannot write the results: {err}") from None
    return [table, matrix]
