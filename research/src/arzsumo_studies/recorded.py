"""An evaluation kept in a record store (``--records DIR``), for studies longer than a
machine lives.

A study of many SUMO runs (the control study's 280, its ablation's 100) outlasts a
session and its machine. With ``--records DIR`` each evaluation of the study copies the
records (:mod:`arzsumo_studies.records`) that ``DIR/<evaluation>/`` holds into its
``--out`` before it runs, runs only what is missing, and copies every finished run back
afterwards, even when interrupted. With ``--report`` nothing runs and no run is written:
each run is read from ``--out`` or else from the store, so a report can be made beside a
running study.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from arzsumo.outdir import resumable_dir
from arzsumo.sweep.evaluate import (
    BASELINE,
    borrowed_baseline,
    check_controllers,
    evaluation_spec,
    run_evaluation,
)
from arzsumo.sweep.evaluate import KIND as EVALUATION_KIND
from arzsumo.sweep.worker import FINISHED
from arzsumo_studies import checks
from arzsumo_studies.common import StudyError
from arzsumo_studies.records import copy_records, records_table

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RecordedRuns:
    """How a study's evaluations run and where their records live.

    ``seeds``: the SUMO seeds; ``records``: the record store (None: none); ``report``:
    run nothing, read the tables from the runs already there; ``runs_from``: earlier
    evaluations or sweeps whose runs are taken instead of run (not with a store or a
    report); ``workers``, ``scheduler``, ``progress``: how the runs are run.

    A ``records`` that is not a usable directory, and ``runs_from`` beside ``records`` or
    ``report``, are refused (their runs live elsewhere: neither store nor report would
    see them), in the command line's terms.
    """

    seeds: tuple[int, ...]
    records: Path | None = None
    report: bool = False
    runs_from: tuple[Path, ...] = ()
    workers: int | None = None
    scheduler: str | None = None
    progress: bool = True

    def __post_init__(self) -> None:
        checks.seeds(self.seeds)
        check_store(self.records, self.report, self.runs_from)


def check_store(records: Path | None, report: bool, runs_from: Sequence[Path] = ()) -> None:
    """Refuse a record store that is not a usable directory, and ``runs_from`` beside a
    store or a report (:class:`RecordedRuns`), in the command line's terms."""
    if runs_from and (records is not None or report):
        flag = "--records" if records is not None else "--report"
        raise StudyError(f"--runs-from = {runs_from[0]} is not allowed with {flag}; "
                         "allowed: one of them")
    if records is None:
        return
    if records.exists() and not records.is_dir():
        raise StudyError(f"--records = {records} is a file; allowed: a directory (made "
                         "when missing)")
    existing = next(p for p in (records, *records.parents) if p.exists())
    if not report and not os.access(existing, os.W_OK | os.X_OK):
        raise StudyError(f"--records = {records} cannot be written; allowed: a directory "
                         "this user can write")


def recorded_evaluation(runs: RecordedRuns, scenario: Path,
                        controllers: Sequence[str], out: Path, *,
                        baseline_from: Path | None = None) -> tuple[pd.DataFrame, bool]:
    """The finished runs of one evaluation of a study, and whether every run finished.

    ``runs`` says how (the store is ``records/<out's name>``). Unless ``report``, the
    evaluation of ``controllers`` on ``scenario`` runs into ``out`` (the store's runs
    copied in first, every finished run out afterwards);
    ``baseline_from``: the open-loop runs are taken from this earlier evaluation (or a
    store laid out as one) instead of run.
    """
    ours = [c for c in check_controllers(controllers)
            if not (baseline_from is not None and c == BASELINE)]
    seeds = list(runs.seeds)
    spec_runs = evaluation_spec(scenario, ours, seeds).runs()
    store = None if runs.records is None else runs.records / out.name
    if runs.report:     # claimed only to hold this evaluation's tables
        with resumable_dir(out, EVALUATION_KIND):
            table = records_table(spec_runs, out, *([store] if store is not None else []))
        if baseline_from is not None:
            table = pd.concat([borrowed_baseline(
                evaluation_spec(scenario, [BASELINE], seeds), baseline_from,
                str(baseline_from)), table], ignore_index=True)
        return table[table["status"].isin(FINISHED)], True
    if store is not None:
        with resumable_dir(out, EVALUATION_KIND):
            log.info("%d run records taken from %s", copy_records(spec_runs, store, out),
                     store)
    try:
        res = run_evaluation(scenario, controllers, seeds, out=out,
                             workers=runs.workers, scheduler=runs.scheduler,
                             progress=runs.progress, plots=False,
                             runs_from=runs.runs_from, baseline_from=baseline_from)
        return res.runs, res.sweep is None or bool(
            res.sweep.table["status"].isin(FINISHED).all())
    finally:
        if store is not None:
            log.info("%d run records added to %s", copy_records(spec_runs, out, store),
                     store)
