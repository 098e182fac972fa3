"""Sweeps executed for real: local pool against a Dask LocalCluster, kill and restart,
invalid and crashing runs, stale results, and a small SUMO sweep."""

from __future__ import annotations

import json
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

from arzsumo.cli import main
from arzsumo.io import FILE_MODE
from arzsumo.sweep import comparable, run_sweep, sweep_from_dict
from arzsumo.sweep.driver import run_local, task_of
from arzsumo.sweep.worker import RunOutcome
from tests.sweep.helpers import PEN, ROOT, SMALL, small_spec


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    # one kernel cache for the module's workers (they inherit the environment)
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path_factory.getbasetemp() / "kernels"))


def write_sweep_file(path: Path, values, seeds, horizon=60) -> Path:
    path.write_text(f"""name = "small"
base = "{ROOT / PEN}"
engine = "twin"
seeds = {list(seeds)}
[set]
initial.kind = "random"
twin.cells = 40
twin.horizon_s = {horizon}
twin.kernel_cells = 40
[[axis]]
field = "equilibrium.penetration"
values = {list(values)}
""")
    return path


def test_local_pool_and_dask_cluster_give_identical_tables(tmp_path):
    from distributed import LocalCluster

    spec = small_spec()
    local = run_sweep(spec, tmp_path / "local", workers=2, progress=False, plots=False)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        dask = run_sweep(spec, tmp_path / "dask", scheduler=cluster.scheduler_address,
                         progress=False, plots=False)
    assert local.executed == dask.executed == 4 and local.statuses == {"ok": 4}
    a = pd.read_parquet(tmp_path / "local" / "summaries.parquet")
    b = pd.read_parquet(tmp_path / "dask" / "summaries.parquet")
    pd.testing.assert_frame_equal(comparable(a), comparable(b))
    assert a["execution.pid"].nunique() == 2                        # two processes worked
    assert set(b["execution.id"]).isdisjoint(a["execution.id"])    # both really executed
    # the axes are columns, the seeds draw different waves, the rows match their summaries
    assert list(a["penetration"]) == [0.44, 0.44, 0.5, 0.5] and list(a["seed"]) == [1, 2] * 2
    assert a.loc[0, "initial_norm"] != a.loc[1, "initial_norm"]
    for _, row in a.iterrows():
        doc = json.loads((tmp_path / "local" / "runs" / row["run_id"] / "summary.json")
                         .read_text())
        assert doc["triggers"] == row["triggers"] and doc["config"]["seed"] == row["seed"]
        ctl = pq.read_table(tmp_path / "local" / "runs" / row["run_id"] / "control.parquet")
        assert int(ctl.column("triggered").to_numpy().sum()) == row["triggers"]


def test_a_killed_sweep_restarts_without_repeating_or_losing_runs(tmp_path):
    sweep = write_sweep_file(tmp_path / "kill.toml", [0.44, 0.46, 0.48, 0.5, 0.52, 0.53],
                             [1, 2], horizon=150)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "arzsumo.cli", "sweep", str(sweep), "--out", str(out),
           "--workers", "1", "--quiet", "--no-plots"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    record = out / "executions.jsonl"     # a run is finished once recorded here

    def recorded() -> dict[str, str]:
        text = record.read_text() if record.is_file() else ""
        whole = text[:text.rfind("\n") + 1]          # a line being written is not yet one
        return {x["run_id"]: x["execution"] for x in map(json.loads, whole.splitlines())}

    deadline = time.monotonic() + 120
    try:
        while len(recorded()) < 3:
            assert proc.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline, "no run finished in 120 s"
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    # a run killed between its result and its record is not finished: it is run again
    before = recorded()
    assert 3 <= len(before) < 12
    assert all(json.loads((out / "runs" / k / "summary.json").read_text())["sweep"]
               ["execution"]["id"] == v for k, v in before.items())
    assert not (out / "summaries.parquet").exists()      # the table comes at the end only
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "2", "--quiet",
                 "--no-plots"]) == 0
    manifest = json.loads((out / "sweep.json").read_text())
    last = manifest["invocations"][-1]
    assert (last["skipped"], last["executed"]) == (len(before), 12 - len(before))
    df = pd.read_parquet(out / "summaries.parquet")
    assert len(df) == 12 and set(df["status"]) == {"ok"}
    after = dict(zip(df["run_id"], df["execution.id"], strict=True))
    assert all(after[k] == v for k, v in before.items())     # finished runs were not redone
    lines = [json.loads(s) for s in record.read_text().splitlines()]
    assert sorted(x["run_id"] for x in lines) == sorted(df["run_id"])  # each once, none lost


def test_an_invalid_run_is_recorded_and_the_others_complete(tmp_path, capsys):
    sweep = write_sweep_file(tmp_path / "bad.toml", [0.44, 1.5], [1])
    out = tmp_path / "out"
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "2", "--quiet"]) == 4
    printed = capsys.readouterr().out
    assert "penetration=1.5,seed=1: invalid: ScenarioError: " in printed
    assert "[equilibrium] penetration = 1.5 is not allowed" in printed
    df = pd.read_parquet(out / "summaries.parquet").set_index("run_id")
    assert df.loc["penetration=0.44,seed=1", "status"] == "ok"
    assert df.loc["penetration=0.44,seed=1", "triggers"] > 0
    bad = df.loc["penetration=1.5,seed=1"]
    assert bad["status"] == "invalid" and "fraction strictly between 0 and 1" in bad["error"]
    assert pd.isna(bad["triggers"])
    err = json.loads((out / "runs" / "penetration=1.5,seed=1" / "error.json").read_text())
    assert err["sweep"]["status"] == "invalid" and "penetration = 1.5" in err["error"]
    assert (out / "plots" / "study.png").stat().st_size > 10_000  # drawn from the good run
    for path in (out / "sweep.toml", out / "summaries.parquet", out / "runs"
                 / "penetration=0.44,seed=1" / "summary.json"):
        assert stat.S_IMODE(path.stat().st_mode) == FILE_MODE       # not 0600 temp files
    # a restart retries the invalid run only
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "1", "--quiet",
                 "--no-plots"]) == 4
    last = json.loads((out / "sweep.json").read_text())["invocations"][-1]
    assert (last["skipped"], last["executed"]) == (1, 1)


def test_a_crashing_worker_is_isolated_and_recorded(tmp_path):
    from tests.sweep.helpers import die_on_crash_run

    spec = small_spec(values=(0.44, 0.47, 0.5), seeds=(1,))
    runs = spec.runs()
    tasks = [task_of(spec, r) for r in runs]
    doomed = tasks[1]
    tasks[1] = type(doomed)(**{**doomed.__dict__,
                               "scenario": {**doomed.scenario, "description": "crash"}})
    outcomes: list[RunOutcome] = []
    run_local(tasks, 2, outcomes.append, fn=die_on_crash_run)
    status = {o.run_id: o.status for o in outcomes}
    assert status == {runs[0].run_id: "ok", runs[1].run_id: "crashed", runs[2].run_id: "ok"}
    assert len(outcomes) == 3                                    # each recorded once
    assert "worker process died" in next(o.error for o in outcomes if o.status == "crashed")


def test_an_edited_sweep_reruns_only_what_changed(tmp_path):
    out = tmp_path / "out"
    first = run_sweep(small_spec(seeds=(1,)), out, workers=1, progress=False, plots=False)
    same = run_sweep(small_spec(seeds=(1,)), out, workers=1, progress=False, plots=False)
    more = run_sweep(small_spec(seeds=(1, 2)), out, workers=1, progress=False, plots=False)
    edited = run_sweep(small_spec(seeds=(1,), fixed={**SMALL, "twin": {
        **SMALL["twin"], "horizon_s": 50}}), out, workers=1, progress=False, plots=False)
    assert (first.executed, same.executed, more.executed, edited.executed) == (2, 0, 2, 2)
    df = pd.read_parquet(out / "summaries.parquet")
    assert list(df["final_time"]) == [50.0, 50.0]


@pytest.mark.sumo
def test_a_sumo_sweep_runs_the_closed_loop(tmp_path):
    data = {"name": "sumo_small", "base": "scenarios/legacy_default.toml", "engine": "sumo",
            "seeds": [5],
            "set": {"sumo": {"horizon_s": 30}, "run": {"warmup_s": 30, "kernel_cells": 40,
                                                       "twin_cells": 40}},
            "axis": [{"field": "run.controller", "values": ["open", "etc"]}]}
    spec = sweep_from_dict(data, "sumo_small.toml", root=ROOT)
    rep = run_sweep(spec, tmp_path / "out", workers=2, progress=False, plots=True)
    assert rep.statuses == {"ok": 2}
    df = pd.read_parquet(tmp_path / "out" / "summaries.parquet").set_index("controller")
    assert df.loc["open", "plan_changes"] == 0 and df.loc["open", "triggers"] == 0
    assert df.loc["etc", "triggers"] >= 1 and df.loc["etc", "seed"] == 5
    # collisions: not counted unless [sumo] collision_check (it changes no vehicle)
    assert (df["horizon"] == 30).all() and df["collisions"].isna().all()
    runs = tmp_path / "out" / "runs"
    for controller in ("open", "etc"):   # SUMO's warnings are kept per run, not printed
        doc = json.loads((runs / f"controller={controller},seed=5" / "summary.json")
                         .read_text(encoding="utf-8"))
        assert df.loc[controller, "warnings"] == len(doc["warnings"])
    periods = pq.read_table(runs / "controller=etc,seed=5" / "periods.parquet")
    assert int(periods.column("triggered").to_numpy().sum()) == df.loc["etc", "triggers"]
