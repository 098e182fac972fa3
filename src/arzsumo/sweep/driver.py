"""Run a sweep: skip finished runs, execute the rest on a process pool or a Dask cluster,
write each outcome as it arrives, then the tidy table, the plots and a manifest.

The output directory (docs/outputs.md, ``arzsumo sweep``) is written one whole run at a
time, so a restart executes exactly the runs without a current result. Both backends call
:func:`arzsumo.sweep.groups.execute_group` (docs/sweeps.md).
"""

from __future__ import annotations

import concurrent.futures as cf
import functools
import json
import logging
import multiprocessing
import os
import time
import uuid
from collections import Counter, deque
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.interrupts import guarded, worker_pool
from arzsumo.io import atomic_file
from arzsumo.outdir import atomic_dir, resumable_dir
from arzsumo.progress import Progress
from arzsumo.sweep.groups import RunGroup, crashed_group, execute_group, share_warmups
from arzsumo.sweep.spec import RunSpec, SweepError, SweepSpec
from arzsumo.sweep.table import (
    RUN_KIND,
    arrow_table,
    read_record,
    run_dir,
    scenario_text,
    sweep_record,
    sweep_table,
)
from arzsumo.sweep.worker import FINISHED, RunOutcome, RunTask, crashed, execute
from arzsumo.version import __version__

log = logging.getLogger(__name__)


@dataclass
class SweepReport:
    """What one invocation of a sweep did."""

    name: str
    out: Path
    backend: str
    total: int
    skipped: int
    executed: int
    statuses: dict[str, int] = field(default_factory=dict)
    wall_time: float = 0.0
    table: pd.DataFrame | None = field(default=None, repr=False)

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "backend": self.backend, "total": self.total,
                "skipped": self.skipped, "executed": self.executed,
                "statuses": self.statuses, "wall_time": self.wall_time,
                "version": __version__, "finished": time.time()}


def task_of(spec: SweepSpec, run: RunSpec) -> RunTask:
    """The picklable task of one run."""
    return RunTask(run.run_id, spec.engine, dict(run.scenario), f"{spec.source} run "
                   f"{run.run_id}", spec.baseline, run.sha256)


def write_outcome(out: Path, run: RunSpec, outcome: RunOutcome) -> None:
    """Store one outcome atomically under ``runs/<run_id>`` and log its execution."""
    record = sweep_record(run, outcome.status, outcome.execution)
    finished = outcome.status in FINISHED and outcome.summary is not None
    head = outcome.summary if finished else {"error": outcome.error}
    doc = {**head, "warnings": outcome.warnings, "sweep": record}
    with atomic_dir(run_dir(out, run), RUN_KIND, overwrite=True) as tmp:
        (tmp / "scenario.toml").write_text(scenario_text(run, outcome.scenario_toml),
                                           encoding="utf-8")
        (tmp / ("summary.json" if finished else "error.json")).write_text(
            json.dumps(doc, indent=2) + "\n", encoding="utf-8")
        if finished:
            for name, blob in outcome.tables.items():
                (tmp / name).write_bytes(blob)
    line = json.dumps({"run_id": run.run_id, "execution": outcome.execution.get("id"),
                       "status": outcome.status})
    with open(out / "executions.jsonl", "a", encoding="utf-8") as fh:
        fh.write(line + "\n")


# -- backends ------------------------------------------------------------------------------
def run_local(tasks: Iterable[Any], workers: int, on_done: Callable[[Any], None],
              fn: Callable[[Any], Any] = execute,
              on_crash: Callable[[Any, str], Any] = crashed) -> None:
    """Execute ``fn`` on ``tasks`` in ``workers`` spawned processes (libsumo holds one
    simulation per process and must not inherit a parent's state).

    At most ``workers`` tasks are in flight, so when a process dies the suspects are
    known: each is run again alone, and one that kills its process again goes to
    ``on_crash`` (task, reason -> outcome, or raise). Any picklable module-level ``fn`` of
    a picklable task works (:func:`map_runs`).
    """
    ctx = multiprocessing.get_context("spawn")
    queue = deque(tasks)
    while queue:
        suspects: list[RunTask] = []
        with worker_pool(max(1, min(workers, len(queue))), ctx) as pool:
            running: dict[cf.Future[RunOutcome], RunTask] = {}
            while (queue or running) and not suspects:
                while queue and len(running) < workers:
                    task = queue.popleft()
                    running[pool.submit(guarded, fn, task)] = task
                done, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
                for fut in done:
                    task = running.pop(fut)
                    try:
                        on_done(fut.result())
                    except BrokenProcessPool:
                        suspects.append(task)
            suspects += list(running.values())
        for task in suspects:
            log.warning("run %s: a worker process died; running it again alone",
                        getattr(task, "run_id", task))
            with worker_pool(1, ctx) as alone:
                try:
                    on_done(alone.submit(guarded, fn, task).result())
                except BrokenProcessPool:
                    on_done(on_crash(task, "the worker process died (twice, the second "
                                           "time running this task alone)"))


def run_dask(tasks: list[Any], address: str, on_done: Callable[[Any], None], one_thread: bool,
             fn: Callable[[Any], Any] = execute,
             on_crash: Callable[[Any, str], Any] = crashed) -> None:
    """Execute ``tasks`` on the Dask cluster whose scheduler is at ``address``; after Dask
    gives up on a task (``KilledWorker``) it goes to ``on_crash``. ``one_thread`` refuses
    workers with more than one thread (libsumo: one simulation per process)."""
    from distributed import Client, as_completed
    from distributed.scheduler import KilledWorker

    try:
        client = Client(address, timeout="15s")
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"--scheduler = {address!r}: cannot reach a Dask scheduler there "
                         f"({exc})") from None
    with client:
        if one_thread:
            wide = {w: n for w, n in client.nthreads().items() if n > 1}
            if wide:
                raise SweepError(f"--scheduler = {address!r}: workers {', '.join(wide)} run "
                                 f"{max(wide.values())} threads; SUMO runs need one "
                                 "simulation per process: start them with --nthreads 1")
        futures = {}
        for i, task in enumerate(tasks):
            fut = client.submit(fn, task, pure=False, key=f"arzsumo-"
                                f"{getattr(task, 'run_id', i)}-{uuid.uuid4().hex[:8]}")
            futures[fut.key] = (fut, task)
        for fut in as_completed([f for f, _ in futures.values()]):
            task = futures[fut.key][1]
            try:
                outcome = fut.result()
            except KilledWorker as exc:
                outcome = on_crash(task, f"Dask gave up after its workers died: {exc}")
            except Exception as exc:  # a worker that cannot import or unpickle arzsumo
                outcome = on_crash(task, f"{type(exc).__name__} on the worker: {exc}")
            on_done(outcome)


def _raise_crash(task: Any, why: str) -> Any:
    raise RuntimeError(f"task {task!r}: {why}")


def map_runs(fn: Callable[[Any], Any], tasks: Sequence[Any], *, workers: int = 1,
             scheduler: str | None = None, in_process: bool = False,
             progress: str | None = None) -> list[Any]:
    """``[fn(t) for t in tasks]`` on the sweep's backends, results in the order of ``tasks``.

    ``fn`` (module-level) and the tasks must be picklable. They run on the Dask cluster of
    ``scheduler``, else on ``workers`` local processes, or with ``in_process`` here, one
    after the other (for runs shorter than a process start). A task whose process dies
    twice raises ``RuntimeError``: unlike a sweep, the caller needs every result.
    ``progress``, when given, labels a progress bar on stderr.
    """
    if in_process or not tasks:
        return [fn(t) for t in tasks]
    results: dict[int, Any] = {}
    indexed = [_Indexed(i, t) for i, t in enumerate(tasks)]
    call = functools.partial(_call_indexed, fn)
    bar = Progress(len(tasks), progress or "", enabled=progress is not None)

    def on_done(pair: tuple[int, Any]) -> None:
        results[pair[0]] = pair[1]
        bar.update(len(results))

    try:
        if scheduler:
            run_dask(indexed, scheduler, on_done, one_thread=False, fn=call,
                     on_crash=_raise_crash)
        else:
            run_local(indexed, workers, on_done, fn=call, on_crash=_raise_crash)
    finally:
        bar.close()
    return [results[i] for i in range(len(tasks))]


@dataclass(frozen=True)
class _Indexed:
    run_id: int
    task: Any


def _call_indexed(fn: Callable[[Any], Any], item: _Indexed) -> tuple[int, Any]:
    return item.run_id, fn(item.task)


# -- the sweep -----------------------------------------------------------------------------
def _finished(out: Path, run: RunSpec) -> bool:
    found = read_record(out, run)
    return found is not None and found[0] in FINISHED


def default_workers() -> int:
    """One process per core (libsumo: one simulation per process)."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
               else (os.cpu_count() or 1))


def run_sweep(spec: SweepSpec, out: str | Path, *, workers: int | None = None,
              scheduler: str | None = None, progress: bool = True,
              plots: bool = True,
              paper: Mapping[str, Mapping[float, float]] | None = None,
              kind: str = "sweep", share_warmup: bool = True) -> SweepReport:
    """Execute the runs of ``spec`` that have no current result under ``out``; then write
    the table, plots and manifest.

    ``out`` is new, empty, or a sweep output of this ``kind`` (marker; ``evaluation``
    for ``arzsumo evaluate``), continued. ``workers``: local processes (default one per
    core), unless ``scheduler`` gives a Dask scheduler's address. ``paper``: reference
    points drawn on ``study.png``, metric -> {axis value: value}. ``share_warmup``: SUMO
    runs that differ only in ``[run] controller`` continue one warm-up (same results).
    """
    t0 = time.perf_counter()
    runs = spec.runs()
    if workers is not None and workers < 1:
        raise SweepError(f"--workers = {workers} is not allowed: an integer >= 1")
    workers = workers or default_workers()
    with resumable_dir(out, kind) as target:
        with atomic_file(target / "sweep.toml") as tmp:
            tmp.write_text(spec.text or f"# sweep {spec.name} (built in code)\n",
                           encoding="utf-8")
        todo = [r for r in runs if not _finished(target, r)]
        by_id = {r.run_id: r for r in runs}
        backend = f"dask {scheduler}" if scheduler else f"local pool, {workers} processes"
        log.info("sweep %s: %d runs, %d finished before, %d to run (%s)", spec.name,
                 len(runs), len(runs) - len(todo), len(todo), backend)
        bar = Progress(len(todo), f"sweep {spec.name}", enabled=progress and bool(todo))
        counts: Counter[str] = Counter()

        def on_group_done(outcomes: list[RunOutcome]) -> None:
            for outcome in outcomes:
                write_outcome(target, by_id[outcome.run_id], outcome)
                counts[outcome.status] += 1
                if outcome.status not in FINISHED:
                    first = outcome.error.splitlines()[0] if outcome.error else ""
                    log.warning("run %s: %s: %s", outcome.run_id, outcome.status, first)
                bar.update(sum(counts.values()))

        tasks = [task_of(spec, r) for r in todo]
        # a seed's runs are split over idle local workers; a cluster's size is not known here
        groups = (share_warmups(tasks, 1 if scheduler else workers) if share_warmup
                  else [RunGroup((t,)) for t in tasks])
        try:
            if groups and scheduler:
                run_dask(groups, scheduler, on_group_done, one_thread=spec.engine == "sumo",
                         fn=execute_group, on_crash=crashed_group)
            elif groups:
                run_local(groups, workers, on_group_done, fn=execute_group,
                          on_crash=crashed_group)
        finally:
            bar.close()
        report = SweepReport(spec.name, target, backend, len(runs), len(runs) - len(todo),
                             sum(counts.values()), dict(counts), time.perf_counter() - t0)
        report.table = finish(spec, target, runs, report, plots, paper)
        return report


def finish(spec: SweepSpec, out: Path, runs: list[RunSpec], report: SweepReport,
           plots: bool, paper: Mapping[str, Mapping[float, float]] | None = None
           ) -> pd.DataFrame:
    """Write the table, plots and manifest of a sweep whose runs are done; return the table."""
    import pyarrow.parquet as pq

    df = sweep_table(runs, out)
    with atomic_file(out / "summaries.parquet") as tmp:
        pq.write_table(arrow_table(df, spec.axes), tmp)
    if plots:
        from arzsumo.outputs.sweep import SweepLayout, write_sweep_plots

        layout = SweepLayout(spec.name, spec.engine, spec.replicate,
                             [(a.name, a.group) for a in spec.axes])
        write_sweep_plots(df[df["status"].isin(FINISHED)], layout, out / "plots", paper)
    manifest_path = out / "sweep.json"
    try:   # the earlier invocations, if any
        history = json.loads(manifest_path.read_text(encoding="utf-8")).get("invocations", [])
    except (OSError, json.JSONDecodeError):
        history = []
    manifest = {"name": spec.name, "description": spec.description, "engine": spec.engine,
                "base": str(spec.base), "version": __version__, "runs": len(runs),
                "statuses": {str(k): int(v) for k, v in df["status"].value_counts().items()},
                "axes": [{"name": a.name, "field": a.field, "group": a.group,
                          "values": list(a.values)} for a in spec.axes],
                "invocations": [*history, report.as_dict()]}
    with atomic_file(manifest_path) as tmp:
        tmp.write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    return df
