"""Run records: a record store is one table; a sweep continued from it runs nothing it
holds and tabulates the same numbers, to the last bit; stale, failed and half-copied
records are handled, and a current record is never replaced by a stale one, in either
direction."""

from __future__ import annotations

import json

import pandas as pd
import pytest
from arzsumo_studies.records import (
    RECORD,
    STORE,
    copy_records,
    holds,
    read_store,
    records_table,
    stored_document,
)
from tests.sweep.helpers import SMALL, small_spec

from arzsumo.outdir import MARKER, resumable_dir
from arzsumo.sweep import comparable, run_sweep
from arzsumo.sweep.table import flatten, run_dir


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path_factory.getbasetemp() / "kernels"))


def spec(horizon=60):
    return small_spec(fixed={**SMALL, "twin": {**SMALL["twin"], "horizon_s": horizon}})


def runs(horizon=60):
    return spec(horizon).runs()


def fingerprints(place) -> set[str]:
    if not (place / "runs").is_dir():
        return {row["sweep.sha256"] for row in read_store(place).values()}
    return {json.loads(p.read_text())["sweep"]["sha256"]
            for p in place.glob("runs/*/summary.json")}


def exactly(d: pd.DataFrame) -> pd.DataFrame:
    """``d`` with its gaps as None (a concatenation may turn a missing None into NaN)."""
    return d.astype(object).where(d.notna(), None)


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "out"
    run_sweep(spec(), out, workers=1, progress=False, plots=False)
    return out


@pytest.fixture(scope="module")
def swept_30(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep30") / "out"
    run_sweep(spec(30), out, workers=1, progress=False, plots=False)
    return out


def test_a_store_is_one_table_of_a_row_per_run(swept, tmp_path):
    store = tmp_path / "store"
    assert copy_records(runs()[:2], swept, store) == 2
    assert copy_records(runs(), swept, store) == 2          # the rest, merged
    assert [p.name for p in store.iterdir()] == [STORE]
    lines = (store / STORE).read_text().splitlines()
    assert len(lines) == 1 + 4          # the column names, a line per run
    assert list(read_store(store)) == sorted(r.run_id for r in runs())
    assert fingerprints(store) == {r.sha256 for r in runs()}
    # a second copy finds every run held
    assert copy_records(runs(), swept, store) == 0


def test_a_sweep_continued_from_records_runs_nothing_and_tabulates_the_same(swept,
                                                                             tmp_path):
    copy_records(runs(), swept, tmp_path / "store")
    fresh = tmp_path / "elsewhere" / "out"
    with resumable_dir(fresh, "sweep"):   # a sweep continues only its own directory
        assert copy_records(runs(), tmp_path / "store", fresh) == 4
    assert len(list(fresh.glob(f"runs/*/{MARKER}"))) == 4
    rep = run_sweep(spec(), fresh, workers=1, progress=False, plots=False)
    assert (rep.executed, rep.skipped) == (0, 4)
    assert not (fresh / "executions.jsonl").exists()    # no execution at all
    before = comparable(pd.read_parquet(swept / "summaries.parquet"))
    after = comparable(rep.table)
    assert set(after.columns) == set(before.columns)
    pd.testing.assert_frame_equal(exactly(after[list(before.columns)]), exactly(before),
                                  check_dtype=False, check_exact=True)
    # each restored scenario is the sweep's own text, so a borrowed open loop checks out
    for run in runs():
        assert (run_dir(fresh, run) / "scenario.toml").read_text() == \
            (run_dir(swept, run) / "scenario.toml").read_text()


def test_a_record_keeps_every_kind_of_scalar(swept, tmp_path):
    """Empty texts, nulls, booleans, integers and floats come back as they were, and a
    table that is null in one run and a subtree in another gives each its own."""
    first, second = runs()[:2]
    odd = {"text": "", "name": "1e3", "none": None, "flag": True, "count": 3,
           "third": 1 / 3, "tiny": 5e-324, "estimation": None}
    for run, extra in ((first, odd), (second, {**odd, "estimation": {"gain": 2.0}})):
        d = run_dir(tmp_path / "src", run)
        d.mkdir(parents=True)
        doc = json.loads((run_dir(swept, run) / "summary.json").read_text())
        (d / "summary.json").write_text(json.dumps({**doc, **extra}))
        (d / "scenario.toml").write_text((run_dir(swept, run) / "scenario.toml").read_text())
    assert copy_records([first, second], tmp_path / "src", tmp_path / "store") == 2
    records = read_store(tmp_path / "store")
    for run in (first, second):
        original = json.loads((run_dir(tmp_path / "src", run) / "summary.json").read_text())
        back = stored_document(records[run.run_id], run)
        assert flatten(back) == flatten(original)


def test_a_stale_record_is_replaced_in_both_directions_and_never_replaces(swept, swept_30,
                                                                          tmp_path):
    store = tmp_path / "store"
    copy_records(runs(60), swept, store)
    # the scenario changed (another horizon): the store's records are stale for it, a
    # sweep of it runs again and its records replace the stale ones
    assert copy_records(runs(30), store, tmp_path / "none") == 0
    assert copy_records(runs(30), swept_30, store) == 4
    assert fingerprints(store) == {r.sha256 for r in runs(30)}
    # the store is current: a directory with stale records does not overwrite it on the
    # way out, and is itself brought up to date on the way in
    stale = tmp_path / "stale"
    copy_records(runs(60), swept, stale)
    assert copy_records(runs(30), stale, store) == 0
    assert copy_records(runs(30), store, stale) == 4
    assert fingerprints(store) == fingerprints(stale) == {r.sha256 for r in runs(30)}


def test_a_current_result_is_kept_and_a_failure_is_superseded(swept, tmp_path):
    run = runs()[0]
    mine = run_dir(tmp_path / "out", run)
    mine.mkdir(parents=True)
    for name in RECORD:
        (mine / name).write_bytes((run_dir(swept, run) / name).read_bytes())
    doc = json.loads((mine / "summary.json").read_text())
    (mine / "summary.json").write_text(json.dumps({**doc, "mine": 1}))
    (mine / "cells.parquet").write_bytes(b"table")
    assert copy_records(runs(), swept, tmp_path / "out") == 3
    assert "mine" in json.loads((mine / "summary.json").read_text())
    failed = run_dir(tmp_path / "failed", run)
    failed.mkdir(parents=True)
    (failed / "error.json").write_text(json.dumps({"sweep": {"sha256": run.sha256,
                                                             "status": "failed"}}))
    assert copy_records(runs(), swept, tmp_path / "failed") == 4
    assert not (failed / "error.json").exists() and holds(tmp_path / "failed", run)


def test_a_half_copied_record_is_not_held_and_is_completed(swept, tmp_path):
    run = runs()[1]
    half = run_dir(tmp_path / "half", run)
    half.mkdir(parents=True)
    (half / "summary.json").write_bytes((run_dir(swept, run) / "summary.json").read_bytes())
    assert not holds(tmp_path / "half", run)           # no scenario
    assert copy_records([run], swept, tmp_path / "half") == 1
    assert holds(tmp_path / "half", run)
    assert not list(half.glob(".*.part"))


def test_unfinished_and_unreadable_runs_are_not_records(swept, tmp_path):
    for run, text in zip(runs()[:3], ['{"sweep": {"status": "failed", "sha256": "%s"}}',
                                      "{not json", '{"no": "sweep"}'], strict=True):
        d = run_dir(tmp_path / "src", run)
        d.mkdir(parents=True)
        (d / "summary.json").write_text(text.replace("%s", run.sha256))
        for n in RECORD[:-1]:
            (d / n).write_text("")
    assert not any(holds(tmp_path / "src", r) for r in runs())
    assert copy_records(runs(), tmp_path / "src", tmp_path / "dst") == 0
    assert all(holds(swept, r) for r in runs())


def test_a_table_of_two_places_reads_each_run_where_it_is_held(swept, tmp_path):
    store, out = tmp_path / "store", tmp_path / "out"
    copy_records(runs()[:2], swept, store)
    copy_records(runs()[2:3], swept, out)
    before = {p: p.stat().st_mtime_ns for p in tmp_path.rglob("*")}
    df = records_table(runs(), out, store)
    assert before == {p: p.stat().st_mtime_ns for p in tmp_path.rglob("*")}   # reads only
    assert list(df["run_id"]) == [r.run_id for r in runs()]
    assert list(df["status"]) == ["ok", "ok", "ok", "missing"]
    whole = comparable(pd.read_parquet(swept / "summaries.parquet")).iloc[:3]
    mine = comparable(df.iloc[:3])[list(whole.columns)]
    pd.testing.assert_frame_equal(exactly(mine), exactly(whole), check_dtype=False,
                                  check_exact=True)
