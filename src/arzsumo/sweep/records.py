"""Run records: the two files of a finished run that a sweep needs to count it as done and
to tabulate it, copied between a sweep's output directory and a record store.

A finished run's directory holds ``scenario.toml`` (the resolved scenario),
``summary.json`` (every measure, and the fingerprint of the scenario that made it) and
the marker of an arzsumo result, beside
larger tables (``periods.parquet``, ``cells.parquet``, ...) that only readings of single
runs need. The two small files are enough for :func:`~arzsumo.sweep.table.read_record` to
find the run finished and for :func:`~arzsumo.sweep.table.sweep_table` to give its row. A
record store is a directory laid out like a sweep's (``runs/<run_id>/``) holding only
those files: kept under version control, it carries a study of many hours across
machines, a later call running only what the store does not hold.

A record is found current by its fingerprint, wherever it was made, so a stale record (a
run of another scenario under the same run ID) is not counted: it is run again and its
record replaced.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from arzsumo.outdir import MARKER
from arzsumo.sweep.worker import FINISHED

#: the files of a run's record: the marker that lets a sweep rewrite the run's directory,
#: the resolved scenario, and the summary (last: its presence makes the run count as done)
RECORD = (MARKER, "scenario.toml", "summary.json")


def finished_runs(out: Path) -> list[Path]:
    """The run directories under ``out/runs`` whose ``summary.json`` records a finished
    run, in name order."""
    found = []
    for summary in sorted(Path(out).glob("runs/*/summary.json")):
        try:
            status = json.loads(summary.read_text(encoding="utf-8"))["sweep"]["status"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if status in FINISHED and all((summary.parent / n).is_file() for n in RECORD):
            found.append(summary.parent)
    return found


def _same(a: Path, b: Path) -> bool:
    return all((b / n).is_file() and (a / n).read_bytes() == (b / n).read_bytes()
               for n in RECORD)


def copy_records(source: Path, target: Path, *, replace: bool) -> int:
    """Copy the record of every finished run under ``source`` to ``target/runs``; return
    how many were copied.

    A run ``target`` holds no finished result of (none, or a failure) is always copied.
    One it holds a finished result of (a full run or a record) is left alone unless
    ``replace``, and then its record files are replaced when they differ (its other files
    stay). ``summary.json``, which makes a run count as done, is moved in last, from a
    temporary name, so ``target`` never holds half of a record. A sweep continues only a
    directory it made, so ``target``, when a sweep's, is claimed first
    (:func:`arzsumo.outdir.resumable_dir`).
    """
    copied = 0
    for run in finished_runs(source):
        dest = Path(target) / "runs" / run.name
        if (dest / "summary.json").is_file() and (not replace or _same(run, dest)):
            continue
        dest.mkdir(parents=True, exist_ok=True)
        (dest / "error.json").unlink(missing_ok=True)
        for name in RECORD:
            tmp = dest / f".{name}.part"
            shutil.copyfile(run / name, tmp)
            tmp.replace(dest / name)
        copied += 1
    return copied
