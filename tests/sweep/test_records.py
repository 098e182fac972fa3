"""Run records: a sweep continued from a record store runs nothing the store holds and
tabulates the same numbers; stale, failed and half-copied records are handled."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from arzsumo.outdir import MARKER, resumable_dir
from arzsumo.sweep import comparable, run_sweep
from arzsumo.sweep.records import RECORD, copy_records, finished_runs
from tests.sweep.helpers import SMALL, small_spec


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path_factory.getbasetemp() / "kernels"))


def spec(horizon=60):
    return small_spec(fixed={**SMALL, "twin": {**SMALL["twin"], "horizon_s": horizon}})


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "out"
    run_sweep(spec(), out, workers=1, progress=False, plots=False)
    return out


def test_a_store_holds_only_the_two_record_files_of_each_run(swept, tmp_path):
    assert copy_records(swept, tmp_path / "store", replace=True) == 4
    files = sorted(p.name for p in (tmp_path / "store").rglob("*") if p.is_file())
    assert files == sorted(RECORD * 4)
    # a second copy finds every record equal
    assert copy_records(swept, tmp_path / "store", replace=True) == 0


def test_a_sweep_continued_from_records_runs_nothing_and_tabulates_the_same(swept,
                                                                             tmp_path):
    copy_records(swept, tmp_path / "store", replace=True)
    fresh = tmp_path / "elsewhere" / "out"
    with resumable_dir(fresh, "sweep"):   # a sweep continues only its own directory
        assert copy_records(tmp_path / "store", fresh, replace=False) == 4
    rep = run_sweep(spec(), fresh, workers=1, progress=False, plots=False)
    assert (rep.executed, rep.skipped) == (0, 4)
    before = comparable(pd.read_parquet(swept / "summaries.parquet"))
    pd.testing.assert_frame_equal(comparable(rep.table), before, check_dtype=False)


def test_a_stale_record_is_run_again_and_replaced_in_the_store(swept, tmp_path):
    store = tmp_path / "store"
    copy_records(swept, store, replace=True)
    out = tmp_path / "out"
    with resumable_dir(out, "sweep"):
        copy_records(store, out, replace=False)
    rep = run_sweep(spec(horizon=30), out, workers=1, progress=False, plots=False)
    assert rep.executed == 4          # another horizon: every record is stale
    assert copy_records(out, store, replace=True) == 4
    doc = json.loads(next(store.rglob("summary.json")).read_text())
    assert doc["sweep"]["sha256"] in {r.sha256 for r in spec(horizon=30).runs()}


def test_a_held_result_is_kept_unless_replacing_and_a_failure_is_superseded(swept,
                                                                           tmp_path):
    run = finished_runs(swept)[0]
    mine = tmp_path / "out" / "runs" / run.name
    mine.mkdir(parents=True)
    (mine / "summary.json").write_text('{"sweep": {"status": "ok"}, "mine": 1}')
    (mine / MARKER).write_bytes((run / MARKER).read_bytes())
    (mine / "cells.parquet").write_bytes(b"table")
    assert copy_records(swept, tmp_path / "out", replace=False) == 3
    assert "mine" in json.loads((mine / "summary.json").read_text())
    assert copy_records(swept, tmp_path / "out", replace=True) == 1
    assert (mine / "summary.json").read_bytes() == (run / "summary.json").read_bytes()
    assert (mine / "cells.parquet").read_bytes() == b"table"
    failed = tmp_path / "failed" / "runs" / run.name
    failed.mkdir(parents=True)
    (failed / "error.json").write_text("{}")
    assert copy_records(swept, tmp_path / "failed", replace=False) == 4
    assert not (failed / "error.json").exists()


def test_unfinished_and_unreadable_runs_are_not_records(swept, tmp_path):
    src = tmp_path / "src" / "runs"
    for name, text in {"a": '{"sweep": {"status": "failed"}}', "b": "{not json",
                       "c": '{"no": "sweep"}'}.items():
        (src / name).mkdir(parents=True)
        (src / name / "summary.json").write_text(text)
        for n in RECORD[:-1]:
            (src / name / n).write_text("")
    assert finished_runs(tmp_path / "src") == []
    assert [p.name for p in finished_runs(swept)] == sorted(p.name for p in
                                                            finished_runs(swept))
    assert len(finished_runs(swept)) == 4
