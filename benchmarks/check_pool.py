"""`labstand diagnose-check`'s campaigns in a plain process pool, one JSON line each as it ends.

For a machine with many cores and no Dask (the check's own ``--workers`` needs it): the
same job (``labstand.commands.diagnose_check.check_job``) on the moderate recordings,
each campaign's scored case (pickled, base64) and diagnosis written the moment it ends,
so a run stopped early keeps what finished. Cap every worker's thread pools first:

    export NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
    .venv/bin/python benchmarks/check_pool.py out/checks.jsonl 16 same:1 same:2 other:3:pairs

A group is ``TRUTH:SEED`` (every class, both weights), ``TRUTH:SEED:pairs`` or
``:triples`` (the standard several-effect campaigns, ``other`` only), or
``TRUTH:SEED:A,B`` (those classes); ``--only TEXT`` keeps the campaigns whose name holds
TEXT (``--only '!TEXT'``: those without it). ``--summary FILE.jsonl`` scores a finished
file (``CheckResult.to_dict()`` per group, and the groups together).
"""

from __future__ import annotations

import argparse
import base64
import json
import pickle
import sys
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def job(item: tuple[str, Any, Any]) -> tuple[str, str, float, str | None, Any, Any]:
    """One campaign: its group, name, seconds, error (or None), case and diagnosis JSON."""
    import labstand.commands.diagnose_check as dc

    group, setup, spec = item
    started = time.perf_counter()
    try:
        case, diagnosis = dc.check_job(setup, spec)
    except Exception:  # reported in its line; the others go on
        return group, spec.name, time.perf_counter() - started, traceback.format_exc(), None, None
    return group, spec.name, time.perf_counter() - started, None, case, diagnosis


def campaigns(groups: list[str]) -> list[tuple[str, Any, Any]]:
    """Every (group, setup, spec) asked for, in the order given."""
    import labstand.commands.diagnose_check as dc
    from sim.checks.check import OUTSIDE_CLASSES, check_cases, recording_set
    from sim.checks.otherstand import OTHER_PAIRS, OTHER_TRIPLES
    from sim.config import load_config

    stand = load_config(None)
    chosen = recording_set("moderate", stand)
    work = []
    for group in groups:
        truth, seed, *extra = group.split(":")
        setup = dc.CheckSetup(stand, chosen, truth, chosen)
        several = {"pairs": OTHER_PAIRS, "triples": OTHER_TRIPLES}
        if extra and extra[0] in several:
            specs = check_cases(int(seed), 1, [], pairs=list(several[extra[0]]))
        elif extra:
            specs = check_cases(int(seed), 1, extra[0].split(","))
        elif truth == "outside":
            specs = check_cases(int(seed), 1, list(OUTSIDE_CLASSES))
        else:
            specs = check_cases(int(seed), 1)
        work += [(group, setup, spec) for spec in specs]
    return work


def kept(name: str, only: str | None) -> bool:
    """Whether ``--only`` keeps a campaign: its name holds the text (``!TEXT``: does not)."""
    if only is None:
        return True
    return only[1:] not in name if only.startswith("!") else only in name


def run(out: Path, workers: int, groups: list[str], only: str | None = None) -> None:
    """Run the campaigns, appending a line per finished one to ``out``."""
    work = [w for w in campaigns(groups) if kept(w[2].name, only)]
    print(f"{len(work)} campaigns on {workers} workers", flush=True)
    started = time.time()
    with out.open("a") as sink, ProcessPoolExecutor(workers) as pool:
        futures = [pool.submit(job, item) for item in work]
        for done, future in enumerate(as_completed(futures), 1):
            group, name, seconds, error, case, diagnosis = future.result()
            line: dict[str, Any] = {"group": group, "name": name, "seconds": seconds,
                                    "error": error}  # fmt: skip
            if case is not None:
                line["case"] = base64.b64encode(pickle.dumps(case)).decode()
                line["diagnosis"] = diagnosis
            sink.write(json.dumps(line, default=str) + "\n")
            sink.flush()
            answer = "ERROR" if error else f"-> {case.answer}"
            print(f"[{time.time() - started:6.0f} s] {done}/{len(work)} {group} {name} "
                  f"{seconds:.0f} s {answer}", flush=True)  # fmt: skip


def summary(path: Path) -> dict[str, Any]:
    """Each group's score, and all groups' together."""
    from sim.checks.check import score

    by_group: dict[str, list[Any]] = {}
    for text in path.read_text().splitlines():
        line = json.loads(text)
        if line.get("case"):
            by_group.setdefault(line["group"], []).append(
                pickle.loads(base64.b64decode(line["case"]))  # our own file
            )
    out = {g: score(cases).to_dict() for g, cases in by_group.items()}
    out["all"] = score([c for cases in by_group.values() for c in cases]).to_dict()
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("workers", type=int, nargs="?", default=1)
    parser.add_argument("groups", nargs="*")
    parser.add_argument("--summary", action="store_true", help="score OUT instead of running")
    parser.add_argument(
        "--only", metavar="TEXT", help="only campaigns whose name holds TEXT (!TEXT: without it)"
    )
    args = parser.parse_args()
    if args.summary:
        print(json.dumps(summary(args.out), indent=1))
    else:
        run(args.out, args.workers, args.groups, args.only)


if __name__ == "__main__":
    main()
