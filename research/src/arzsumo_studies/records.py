"""Run records: what a sweep needs of a finished run to count it done and to tabulate it,
kept in one compact table (a *record store*) and copied between it and a sweep's output
directory.

A finished run's directory (``runs/<run_id>/``) holds ``scenario.toml`` (the resolved
scenario), ``summary.json`` (every measure, and the fingerprint of the scenario that made
it) and larger tables (``periods.parquet``, ``cells.parquet``, ...) that only readings of
single runs need. Its *record* is one row: its identity, fingerprint, status, warnings and
execution (columns ``sweep.*``, a name no summary entry takes) and every scalar of its
summary (dotted names, as in the sweep's table; the summary's lists are not kept). A record
store is a directory holding ``records.jsonl``: a first line of column names, then one
line per run (its values, JSON, in that order), sorted by run ID, so the values come back
exactly (texts, integers, booleans, nulls and the last bit of each float) and a diff shows
the runs a commit added. Kept under version control, a store carries a study of many hours
across machines, a later call running only what the store does not hold. A place is a
store when it has that table or has neither the marker nor the ``runs/`` of a sweep's
directory (a missing one is an empty store).

Copied from a store into a sweep's directory, a record becomes a run directory again:
``scenario.toml`` from the run's own resolved scenario (the text the sweep writes),
``summary.json`` from the row, and the marker of an arzsumo result, so the sweep skips the
run and may later rewrite its directory.

Whether a place holds a run is decided by the run's fingerprint (the SHA-256 of its
resolved scenario), wherever the record was made: a stale record (a run of another
scenario under the same run ID) counts as absent, in a sweep's directory and in a store
alike, so it never replaces a current one and is itself replaced by one.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.io import atomic_file, dump_toml, json_safe
from arzsumo.outdir import marker_kind, write_marker
from arzsumo.sweep.spec import RunSpec
from arzsumo.sweep.table import (
    RUN_KIND,
    flatten,
    read_record,
    run_dir,
    scenario_text,
    sweep_record,
    table_row,
    uniform_types,
)
from arzsumo.sweep.worker import FINISHED

#: the files of a run's record in a sweep's directory: the resolved scenario, and the
#: summary (last: its presence makes the run count as done)
RECORD = ("scenario.toml", "summary.json")
#: the table of a record store
STORE = "records.jsonl"
#: the columns of a record that are not its summary's (``sweep.execution.*`` follow)
RUN_ID, SHA256, STATUS, WARNINGS = "sweep.run_id", "sweep.sha256", "sweep.status", \
    "sweep.warnings"
EXECUTION = "sweep.execution."

Records = dict[str, dict[str, Any]]


def is_store(place: Path) -> bool:
    """Whether ``place`` is a record store (module docstring)."""
    return (place / STORE).is_file() or (marker_kind(place) is None
                                         and not (place / "runs").is_dir())


def read_store(store: Path) -> Records:
    """The records of ``store`` by run ID (none when it has no table)."""
    path = store / STORE
    if not path.is_file():
        return {}
    lines = path.read_text(encoding="utf-8").splitlines()
    columns = json.loads(lines[0]) if lines else []
    rows = (dict(zip(columns, json.loads(line), strict=True)) for line in lines[1:])
    return {row[RUN_ID]: row for row in rows}


def _current(records: Records, run: RunSpec) -> dict[str, Any] | None:
    """The record of ``run`` if ``records`` holds it finished from its current scenario."""
    row = records.get(run.run_id)
    if row is None or row[SHA256] != run.sha256 or row[STATUS] not in FINISHED:
        return None
    return row


def _unflatten(flat: Mapping[str, Any]) -> dict[str, Any]:
    """The nested document of dotted names (the inverse of table.flatten).

    A store's table has the columns of all its runs: where one run has ``estimation =
    None`` and another ``estimation.gain = 2``, the first run's row is null under
    ``estimation.gain`` and the second's under ``estimation``. The values decide: a null
    is placed only where no value is, the shortest null name of an empty subtree first.
    """
    out: dict[str, Any] = {}
    nulls = sorted((k for k, v in flat.items() if v is None), key=lambda k: k.count("."))
    for name in [*(k for k, v in flat.items() if v is not None), *nulls]:
        *path, leaf = name.split(".")
        node: Any = out
        for part in path:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                break
        else:
            if flat[name] is not None or not isinstance(node.get(leaf), dict):
                node[leaf] = flat[name]
    return out


def stored_document(record: Mapping[str, Any], run: RunSpec) -> dict[str, Any]:
    """The ``summary.json`` document of a store's ``record`` of ``run``."""
    doc = _unflatten({k: v for k, v in record.items() if not k.startswith("sweep.")})
    execution = {k.removeprefix(EXECUTION): v for k, v in record.items()
                 if k.startswith(EXECUTION)}
    doc["warnings"] = list(record.get(WARNINGS) or [])
    doc["sweep"] = sweep_record(run, str(record[STATUS]), execution)
    return doc


def _record_of(out: Path, run: RunSpec) -> dict[str, Any] | None:
    """The record of ``run`` in a sweep's directory ``out``, if it holds it."""
    if not holds(out, run):
        return None
    status, doc = read_record(out, run)   # type: ignore[misc]
    execution = doc.get("sweep", {}).get("execution", {})
    return json_safe({RUN_ID: run.run_id, SHA256: run.sha256, STATUS: status,
                      WARNINGS: list(doc.get("warnings", [])),
                      **{f"{EXECUTION}{k}": v for k, v in execution.items()},
                      **flatten(doc)})


def holds(place: Path, run: RunSpec) -> bool:
    """Whether ``place`` (a sweep's directory or a store) holds the whole record of
    ``run`` finished, from its current scenario (fingerprint)."""
    if is_store(place):
        return _current(read_store(place), run) is not None
    found = read_record(place, run)
    return (found is not None and found[0] in FINISHED
            and all((run_dir(place, run) / n).is_file() for n in RECORD))


@contextlib.contextmanager
def _locked(store: Path) -> Iterator[None]:
    """Hold the store's lock: two studies adding to one store do not lose each other's
    records (each reads, merges and replaces the table under it)."""
    store.mkdir(parents=True, exist_ok=True)
    fd = os.open(store, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _write_store(records: Records, store: Path) -> None:
    """Write the store's table whole through a temporary file: rows by run ID, columns in
    first-seen order (the identity first, then as the summaries list them)."""
    columns = list(dict.fromkeys(k for row in records.values() for k in row))
    lines = [json.dumps(columns)]
    lines += [json.dumps([records[r].get(c) for c in columns], allow_nan=False)
              for r in sorted(records)]
    with atomic_file(store / STORE) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _place(texts: Mapping[str, str], dest: Path) -> None:
    """Write a run's record files ``texts`` into its directory ``dest``: the old summary
    goes first, then the marker, the scenario, and the summary last, each through a
    temporary file, so ``dest`` never pairs a summary with another run's scenario and an
    interrupted copy leaves a run that counts as not done."""
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("summary.json", "error.json"):
        (dest / name).unlink(missing_ok=True)
    write_marker(dest, RUN_KIND)
    for name in RECORD:
        with atomic_file(dest / name) as tmp:
            tmp.write_text(texts[name], encoding="utf-8")


def _texts_of(record: Mapping[str, Any], run: RunSpec) -> dict[str, str]:
    """The record files of a store's ``record`` of ``run``."""
    return {"scenario.toml": scenario_text(run, dump_toml(dict(run.scenario))),
            "summary.json": json.dumps(stored_document(record, run), indent=2) + "\n"}


def _into_directory(runs: Sequence[RunSpec], source: Path, target: Path) -> int:
    """:func:`copy_records` into a sweep's directory ``target``."""
    records = read_store(source) if is_store(source) else None
    copied = 0
    for run in runs:
        if holds(target, run):
            continue
        if records is None:
            if holds(source, run):
                _place({n: (run_dir(source, run) / n).read_text(encoding="utf-8")
                        for n in RECORD}, run_dir(target, run))
                copied += 1
        elif (record := _current(records, run)) is not None:
            _place(_texts_of(record, run), run_dir(target, run))
            copied += 1
    return copied


def copy_records(runs: Iterable[RunSpec], source: Path, target: Path) -> int:
    """Copy the record of every run of ``runs`` that ``source`` holds and ``target`` does
    not (:func:`holds`) from ``source`` to ``target``, each a sweep's directory or a
    store; return how many.

    A current finished result in ``target`` is never replaced; a stale or failed one is.
    A sweep continues only a directory it made, so ``target``, when a sweep's, is claimed
    first (:func:`arzsumo.outdir.resumable_dir`).
    """
    runs = list(runs)
    if not is_store(target):
        return _into_directory(runs, source, target)
    with _locked(target):
        held = read_store(target)
        theirs = read_store(source) if is_store(source) else None
        new = {}
        for run in runs:
            if _current(held, run) is None:
                row = (_record_of(source, run) if theirs is None
                       else _current(theirs, run))
                if row is not None:
                    new[run.run_id] = row
        if new:
            _write_store({**held, **new}, target)
        return len(new)


def records_table(runs: Sequence[RunSpec], *places: Path) -> pd.DataFrame:
    """:func:`~arzsumo.sweep.table.sweep_table` of ``runs``, each run read from the first
    of ``places`` (sweeps' directories or stores) that holds it (a run none holds: as the
    first place has it), in the order of ``runs``. Reads only: a running sweep's
    directory can be one of the places."""
    stores = {p: read_store(p) for p in places if is_store(p)}

    def found(run: RunSpec) -> tuple[str, dict[str, Any]] | None:
        for place in places:
            if place in stores:
                if (record := _current(stores[place], run)) is not None:
                    return str(record[STATUS]), stored_document(record, run)
            elif holds(place, run):
                return read_record(place, run)
        return None if not places or places[0] in stores else read_record(places[0], run)

    return pd.DataFrame([table_row(run, found(run)) for run in runs]).apply(uniform_types)
