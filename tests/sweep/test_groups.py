"""A sweep's runs of one seed share a warm-up; a killed branch runs again alone; a
killed sweep leaves no worker behind."""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from arzsumo.io import dump_toml
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.sumo.fork import can_fork
from arzsumo.sweep.groups import CHILD_COMMAND, RunGroup, share_warmups, warmup_key
from arzsumo.sweep.worker import RunTask, execute

DEFAULT = shipped_scenarios_dir() / "default.toml"


def task(controller: str, seed: int = 5, engine: str = "sumo", **sumo) -> RunTask:
    data = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    data["run"].update(controller=controller, warmup_s=60.0, kernel_cells=50, twin_cells=50)
    data["sumo"].update(seed=seed, horizon_s=40.0, drain_max_s=0.0, **sumo)
    return RunTask(f"{controller},seed={seed}", engine, data, str(DEFAULT), False, "x")


def test_runs_group_by_everything_but_the_controller():
    tasks = [task(c, s) for s in (1, 2) for c in ("open", "etc", "alinea")]
    groups = share_warmups(tasks, workers=1)
    assert [[t.run_id for t in g.tasks] for g in groups] == [
        ["open,seed=1", "etc,seed=1", "alinea,seed=1"],
        ["open,seed=2", "etc,seed=2", "alinea,seed=2"]]
    assert warmup_key(task("open", ramp_demand_veh_h=500.0)) != warmup_key(task("open"))
    # fewer groups than workers: the largest are halved until every worker has one
    assert sorted(len(g.tasks) for g in share_warmups(tasks, workers=4)) == [1, 1, 2, 2]
    assert all(len(g.tasks) == 1 for g in share_warmups(tasks[:3], workers=8))
    twins = share_warmups([task("open", engine="twin"), task("etc", engine="twin")])
    assert [len(g.tasks) for g in twins] == [1, 1]          # no SUMO warm-up to share


def test_what_acts_only_in_the_window_shares_the_warmup():
    base = task("open")
    constant = task("constant")
    constant.scenario["run"]["constant_release_veh_h"] = 480.0
    disturbed = task("etc")
    disturbed.scenario["disturbance"] = {"kind": "slowdown", "duration_s": 20.0}
    assert warmup_key(constant) == warmup_key(base) == warmup_key(disturbed)
    longer = task("open")
    longer.scenario["run"]["warmup_s"] = 90.0          # the warm-up itself: not shared
    assert warmup_key(longer) != warmup_key(base)


def _table(blob: bytes) -> pa.Table:
    return pq.read_table(pa.BufferReader(blob))


def _numbers(summary: dict) -> dict:
    return {k: v for k, v in summary.items()
            if k not in ("wall_time", "timings", "controller_time_per_period")}


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _started(pid: int) -> tuple[str, str] | None:
    """(state, start time) of process ``pid``, None when there is none. The start time
    tells a process from a later one under the same reused PID (pid_max may be 32768)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return fields[0], fields[19]


def _alive(pid: int, started: tuple[str, str] | None) -> bool:
    """Whether the process that had ``started`` still runs (a zombie has exited)."""
    now = _started(pid)
    return now is not None and started is not None and now[1] == started[1] \
        and now[0] != "Z"


def _children(pid: int) -> list[int]:
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


@pytest.mark.sumo
@pytest.mark.slow
@pytest.mark.skipif(not can_fork(), reason="needs fork and /proc")
def test_a_group_with_a_killed_branch_completes_and_equals_plain_runs(tmp_path):
    group = RunGroup((task("open"), task("etc")))
    scratch = tmp_path / "scratch"
    env = {**os.environ, "ARZSUMO_SCRATCH_DIR": str(scratch),
           "ARZSUMO_CACHE": str(tmp_path / "cache")}
    proc = subprocess.Popen(CHILD_COMMAND, env=env,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    proc.stdin.write(pickle.dumps(group))
    proc.stdin.close()
    killed, deadline, seen = None, time.monotonic() + 300, {}
    while killed is None and time.monotonic() < deadline and proc.poll() is None:
        now = time.monotonic()
        kids = [k for k in _children(proc.pid)   # the first branch, forked after the warm-up
                if b"arzsumo.sweep.groups" in _cmdline(k)]     # (not netconvert)
        # a child that still carries the parent's command line 0.5 s on is a branch: one
        # forked to exec SUMO's tools does so within milliseconds (longer under load, when
        # killing it would fail the warm-up instead)
        old = [k for k in kids if now - seen.setdefault(k, now) >= 0.5]
        if old:
            killed = old[0]
            os.kill(killed, signal.SIGKILL)
        time.sleep(0.02)
    outcomes = pickle.loads(proc.stdout.read())
    assert proc.wait() == 0 and killed is not None
    assert [o.status for o in outcomes] == ["ok", "ok"]
    assert "rerun_alone" in outcomes[0].execution            # the killed one, run alone
    assert outcomes[1].execution["shared_warmup"] == 2
    assert list(scratch.iterdir()) == [] and _children(proc.pid) == []
    os.environ.setdefault("ARZSUMO_CACHE", str(tmp_path / "cache"))
    for got, t in zip(outcomes, group.tasks, strict=True):   # both equal plain runs
        plain = execute(t)
        assert _numbers(got.summary) == _numbers(plain.summary)
        # as frames: NaN where the other has NaN is equal (the trigger's columns of a
        # law without a trigger)
        for name in ("periods.parquet", "cells.parquet"):
            assert _table(got.tables[name]).to_pandas().equals(
                _table(plain.tables[name]).to_pandas()), name


@pytest.mark.sumo
@pytest.mark.slow
@pytest.mark.skipif(not can_fork(), reason="needs fork and /proc")
def test_a_terminated_sweep_leaves_no_worker_and_no_file(tmp_path):
    scenario = tmp_path / "sc.toml"
    data = task("open").scenario
    data["sumo"]["horizon_s"] = 600.0
    scenario.write_text(dump_toml(data), encoding="utf-8")
    out = tmp_path / "ev"
    proc = subprocess.Popen([sys.executable, "-m", "arzsumo", "evaluate", str(scenario),
                             "--controllers", "open", "--seeds", "2", "--workers", "2",
                             "--allow-short-warmup",
                             "--out", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def in_scratch() -> list[Path]:   # the run's scratch directory: SUMO's files
        return [f for d in out.glob(".scratch.*") for f in d.rglob("*")]

    def runs_started() -> int:        # each run makes 3 directories: SUMO's, its outputs'
        return sum(1 for f in in_scratch() if f.name.startswith("arzsumo-"))  # and kept

    def workers() -> list[int]:
        return [p for p in _children(proc.pid) if b"spawn_main" in _cmdline(p)]

    deadline = time.monotonic() + 120     # both workers in SUMO: 3 scratch entries a run
    while time.monotonic() < deadline and (len(workers()) < 2 or runs_started() < 6):
        time.sleep(0.2)
    pool = {p: _started(p) for p in workers()}
    assert len(pool) == 2 and runs_started() >= 6
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=30)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and any(_alive(p, t) for p, t in pool.items()):
        time.sleep(0.2)
    assert not any(_alive(p, t) for p, t in pool.items())
    assert in_scratch() == []             # each worker closed SUMO and removed its files


@pytest.mark.sumo
@pytest.mark.slow
def test_a_group_on_dask_runs_in_a_process_of_its_own_and_equals_the_local_pool(tmp_path):
    from distributed import LocalCluster

    from arzsumo.sweep.driver import run_sweep
    from arzsumo.sweep.spec import sweep_from_dict
    from arzsumo.sweep.table import comparable

    spec = sweep_from_dict({
        "name": "groups", "base": str(DEFAULT), "engine": "sumo", "seeds": [5],
        "set": {"run.warmup_s": 60.0, "run.kernel_cells": 50, "run.twin_cells": 50,
                "sumo.horizon_s": 40.0, "sumo.drain_max_s": 0.0},
        "axis": [{"field": "run.controller", "values": ["open", "etc"]}]},
        "test", root=DEFAULT.parent)
    local = run_sweep(spec, tmp_path / "local", workers=1, progress=False, plots=False)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        dask = run_sweep(spec, tmp_path / "dask", scheduler=cluster.scheduler_address,
                         progress=False, plots=False)
    assert local.statuses == dask.statuses == {"ok": 2}
    a = pd.read_parquet(tmp_path / "local" / "summaries.parquet")
    b = pd.read_parquet(tmp_path / "dask" / "summaries.parquet")
    assert list(a["execution.shared_warmup"]) == list(b["execution.shared_warmup"]) == [2, 2]
    pd.testing.assert_frame_equal(comparable(a), comparable(b))
