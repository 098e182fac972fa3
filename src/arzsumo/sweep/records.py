"""Run records: the two small files of a finished run that a sweep needs to count it as
done and to tabulate it, copied between a sweep's output directory and a record store.

A finished run's directory holds ``scenario.toml`` (the resolved scenario) and
``summary.json`` (every measure, and the fingerprint of the scenario that made it), beside
the marker of an arzsumo result and larger tables (``periods.parquet``, ``cells.parquet``,
...) that only readings of single runs need. The two small files are enough for
:func:`~arzsumo.sweep.table.read_record` to find the run finished and for
:func:`~arzsumo.sweep.table.sweep_table` to give its row. A record store is a directory
laid out like a sweep's (``runs/<run_id>/``) holding only those two files (and the
marker, below): kept under version control, it carries a study of many hours across
machines, a later call running only what the store does not hold. The marker is not
part of a record (version control may ignore it, as this repository's does): it is
written afresh wherever a record is copied to, so the sweep may later rewrite that run's
directory.

Whether a directory holds a run is decided by the run's fingerprint (the SHA-256 of its
resolved scenario), wherever the record was made: a stale record (a run of another
scenario under the same run ID) counts as absent, in a sweep's directory and in a store
alike, so it never replaces a current one and is itself replaced by one.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path

import pandas as pd

from arzsumo.outdir import write_marker
from arzsumo.sweep.spec import RunSpec
from arzsumo.sweep.table import RUN_KIND, read_record, run_dir, sweep_table
from arzsumo.sweep.worker import FINISHED

#: the files of a run's record: the resolved scenario, and the summary (last: its presence
#: makes the run count as done)
RECORD = ("scenario.toml", "summary.json")


def holds(out: Path, run: RunSpec) -> bool:
    """Whether ``out`` holds the whole record of ``run`` finished, from its current
    scenario (fingerprint)."""
    found = read_record(out, run)
    return (found is not None and found[0] in FINISHED
            and all((run_dir(out, run) / n).is_file() for n in RECORD))


def _copy_record(source: Path, dest: Path) -> None:
    """Copy one record's files from ``source`` to ``dest``, its other files left alone.

    The old ``summary.json`` goes first, then the marker of a sweep's run is written, and
    the new summary comes last, each file through a temporary name of its own, so
    ``dest`` never pairs a summary with another run's scenario, and an interrupted copy
    leaves a run that counts as not done.
    """
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("summary.json", "error.json"):
        (dest / name).unlink(missing_ok=True)
    write_marker(dest, RUN_KIND)
    for name in RECORD:
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".part", dir=dest)
        os.close(fd)
        try:
            shutil.copyfile(source / name, tmp)
            Path(tmp).replace(dest / name)
        finally:
            Path(tmp).unlink(missing_ok=True)


def copy_records(runs: Iterable[RunSpec], source: Path, target: Path) -> int:
    """Copy the record of every run of ``runs`` that ``source`` holds and ``target`` does
    not (:func:`holds`) from ``source/runs`` to ``target/runs``; return how many.

    A current finished result in ``target`` is never replaced; a stale or failed one is.
    A sweep continues only a directory it made, so ``target``, when a sweep's, is claimed
    first (:func:`arzsumo.outdir.resumable_dir`).
    """
    copied = 0
    for run in runs:
        if holds(source, run) and not holds(target, run):
            _copy_record(run_dir(source, run), run_dir(target, run))
            copied += 1
    return copied


def records_table(runs: Sequence[RunSpec], *places: Path) -> pd.DataFrame:
    """:func:`~arzsumo.sweep.table.sweep_table` of ``runs``, each run read from the first
    of ``places`` that holds it (a run none holds: as the first place has it), in the
    order of ``runs``. Reads only: a running sweep's directory can be one of the places."""
    where: dict[int, list[RunSpec]] = {}
    for run in runs:
        i = next((i for i, p in enumerate(places) if holds(p, run)), 0)
        where.setdefault(i, []).append(run)
    parts = [sweep_table(group, places[i]) for i, group in sorted(where.items())]
    order = {run.run_id: k for k, run in enumerate(runs)}
    df = pd.concat(parts, ignore_index=True)
    return df.sort_values("run_id", key=lambda s: s.map(order)).reset_index(drop=True)
