"""The runs of a study's design, executed through the sweep engine and stored resumably.

A study whose runs are not plain closed-loop runs (its own measurement loop in SUMO, an
offline pass over a record) still expands its design as a sweep built in code
(:func:`arzsumo.sweep.spec.sweep_from_dict`: base scenario, axes, seeds, stable run IDs)
and runs it on the sweep's backends (:func:`arzsumo.sweep.driver.run_local`,
:func:`~arzsumo.sweep.driver.run_dask`) with its own worker function. Each finished
run's row is written atomically to ``OUT/runs/<run_id>.json`` with the SHA-256 of what
decides it (the resolved scenario and the study's options), so a second call with the
same directory runs only the runs without a current row.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arzsumo.io import atomic_file, json_safe
from arzsumo.progress import Progress
from arzsumo.sweep.driver import default_workers, run_dask, run_local
from arzsumo.sweep.spec import SweepSpec

log = logging.getLogger(__name__)

#: a study's worker: one run in, one JSON-able row (a mapping) out
Worker = Callable[["StudyRun"], Mapping[str, Any]]


@dataclass(frozen=True)
class StudyRun:
    """One run of a study (picklable: no file handles, no paths that must exist).

    ``scenario``: the resolved scenario tables; ``columns``: the run's axis values (the
    table columns that identify it); ``options``: the study's settings that are not
    scenario keys (JSON-able).
    """

    run_id: str
    scenario: Mapping[str, Any]
    columns: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)
    source: str = "<study>"

    @property
    def sha256(self) -> str:
        """Fingerprint of everything that decides the run's row."""
        blob = json.dumps({"scenario": self.scenario, "options": self.options},
                          sort_keys=True, default=str)
        return hashlib.sha256(blob.encode()).hexdigest()


def design_runs(spec: SweepSpec, options: Mapping[str, Any] | None = None) -> list[StudyRun]:
    """The runs of the sweep ``spec`` (axes in order, seeds last) with the study's
    ``options``."""
    return [StudyRun(r.run_id, dict(r.scenario), dict(r.columns), dict(options or {}),
                     f"{spec.source} run {r.run_id}") for r in spec.runs()]


def _stored(out: Path, run: StudyRun) -> dict[str, Any] | None:
    path = out / "runs" / f"{run.run_id}.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None
    return doc.get("row") if doc.get("sha256") == run.sha256 else None


def _keyed(fn: Worker, run: StudyRun) -> tuple[str, Any]:
    return run.run_id, json_safe(dict(fn(run)))


def _crash(run: Any, why: str) -> Any:
    raise RuntimeError(f"run {getattr(run, 'run_id', run)}: {why}")


def run_design(runs: Sequence[StudyRun], fn: Worker, out: Path, *,
               workers: int | None = None, scheduler: str | None = None,
               progress: bool = True, label: str = "study",
               in_process: bool = False) -> list[dict[str, Any]]:
    """The rows of ``runs`` (in their order): read from ``out/runs`` where current, the
    rest computed by ``fn`` (a picklable module-level function) on the sweep's backends.

    Parameters
    ----------
    runs : sequence of StudyRun
    fn : callable
        The worker; an exception it raises stops the study (the rows finished so far are
        kept), a worker process that dies twice raises ``RuntimeError``.
    out : Path
        The study's (claimed) output directory.
    workers : int, optional
        Local processes (default: one per core).
    scheduler : str, optional
        Address of a Dask scheduler to run on instead.
    in_process : bool
        Run ``fn`` here, one run after the other (for runs shorter than a process start).
    """
    rows: dict[str, dict[str, Any]] = {}
    for run in runs:
        found = _stored(out, run)
        if found is not None:
            rows[run.run_id] = found
    # a run listed twice (e.g. a point and its fuller-fill variant share their discharge
    # runs) is run once; every listing reads its row
    by_id = {r.run_id: r for r in runs}
    todo = [r for r in by_id.values() if r.run_id not in rows]
    before = len(rows)
    log.info("%s: %d runs, %d finished before, %d to run", label, len(by_id), before,
             len(todo))
    bar = Progress(len(todo), label, enabled=progress and bool(todo))

    def on_done(pair: tuple[str, dict[str, Any]]) -> None:
        run_id, row = pair
        with atomic_file(out / "runs" / f"{run_id}.json") as tmp:
            doc = {"run_id": run_id, "sha256": by_id[run_id].sha256, "row": row}
            tmp.write_text(json.dumps(doc) + "\n", encoding="utf-8")
        rows[run_id] = row
        bar.update(len(rows) - before)

    call = functools.partial(_keyed, fn)
    try:
        if in_process:
            for run in todo:
                on_done(call(run))
        elif todo and scheduler:
            run_dask(todo, scheduler, on_done, one_thread=True, fn=call, on_crash=_crash)
        elif todo:
            run_local(todo, workers or default_workers(), on_done, fn=call, on_crash=_crash)
    finally:
        bar.close()
    return [rows[r.run_id] for r in runs]
