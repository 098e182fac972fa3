"""An evaluation kept in a record store (``--records DIR``), for studies longer than a
machine lives.

A study of many SUMO runs (the control study's 280, its ablation's 100) outlasts a
session and its machine. With ``--records DIR`` each evaluation of the study copies the
records (:mod:`arzsumo.sweep.records`) that ``DIR/<evaluation>/`` holds into its
``--out`` before it runs, runs only what is missing, and copies every finished run back
afterwards, even when interrupted. With ``--report`` nothing runs and no run is written:
each run is read from ``--out`` or else from the store, so a report can be made beside a
running study.
"""

from __future__ import annotations

import argparse
import logging
import os
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.studies.common import StudyError
from arzsumo.sweep.evaluate import (
    BASELINE,
    borrowed_baseline,
    check_controllers,
    evaluation_spec,
    run_evaluation,
)
from arzsumo.sweep.evaluate import KIND as EVALUATION_KIND
from arzsumo.sweep.records import copy_records, records_table
from arzsumo.sweep.worker import FINISHED

log = logging.getLogger(__name__)


def add_records(parser: argparse.ArgumentParser) -> None:
    """``--report`` and ``--records``."""
    parser.add_argument("--report", action="store_true",
                        help="run nothing: the tables from the runs already there "
                             "(finished so far, while a study is running too)")
    parser.add_argument("--records", type=Path, metavar="DIR",
                        help="a store of run records (a table per experiment, "
                             "DIR/<experiment>/records.jsonl, a line per finished run): "
                             "the runs it holds are not run again, and every finished run "
                             "is added to it; kept under version control, it carries the "
                             "study across machines")


def check_records(args: argparse.Namespace) -> None:
    """Refuse a ``--records`` that is not a usable directory, and ``--runs-from`` beside
    ``--records`` or ``--report`` (their runs live elsewhere: neither store nor report
    would see them)."""
    runs_from = getattr(args, "runs_from", None)
    if runs_from and (args.records is not None or args.report):
        flag = "--records" if args.records is not None else "--report"
        raise StudyError(f"--runs-from = {runs_from[0]} is not allowed with {flag}; "
                         "allowed: one of them")
    if args.records is None:
        return
    if args.records.exists() and not args.records.is_dir():
        raise StudyError(f"--records = {args.records} is a file; allowed: a directory "
                         "(made when missing)")
    existing = next(p for p in (args.records, *args.records.parents) if p.exists())
    if not args.report and not os.access(existing, os.W_OK | os.X_OK):
        raise StudyError(f"--records = {args.records} cannot be written; allowed: a "
                         "directory this user can write")


def recorded_evaluation(args: argparse.Namespace, scenario: Path,
                        controllers: Sequence[str], out: Path, *,
                        baseline_from: Path | None = None) -> tuple[pd.DataFrame, bool]:
    """The finished runs of one evaluation of a study, and whether every run finished.

    ``args`` carries the study's ``seeds``, ``workers``, ``scheduler``, ``quiet``,
    ``report``, ``records`` (the store is ``records/<out's name>``) and ``runs_from``.
    Unless ``--report``, the evaluation of ``controllers`` on ``scenario`` runs into
    ``out`` (the store's runs copied in first, every finished run out afterwards);
    ``baseline_from``: the open-loop runs are taken from this earlier evaluation (or a
    store laid out as one) instead of run.
    """
    ours = [c for c in check_controllers(controllers)
            if not (baseline_from is not None and c == BASELINE)]
    spec_runs = evaluation_spec(scenario, ours, args.seeds).runs()
    store = None if args.records is None else args.records / out.name
    if args.report:     # claimed only to hold this evaluation's tables
        with resumable_dir(out, EVALUATION_KIND):
            runs = records_table(spec_runs, out, *([store] if store is not None else []))
        if baseline_from is not None:
            runs = pd.concat([borrowed_baseline(
                evaluation_spec(scenario, [BASELINE], args.seeds), baseline_from,
                str(baseline_from)), runs], ignore_index=True)
        return runs[runs["status"].isin(FINISHED)], True
    if store is not None:
        with resumable_dir(out, EVALUATION_KIND):
            log.info("%d run records taken from %s", copy_records(spec_runs, store, out),
                     store)
    try:
        res = run_evaluation(scenario, controllers, args.seeds, out=out,
                             workers=args.workers, scheduler=args.scheduler,
                             progress=not args.quiet, plots=False,
                             runs_from=getattr(args, "runs_from", ()),
                             baseline_from=baseline_from)
        return res.runs, res.sweep is None or bool(
            res.sweep.table["status"].isin(FINISHED).all())
    finally:
        if store is not None:
            log.info("%d run records added to %s", copy_records(spec_runs, out, store),
                     store)
