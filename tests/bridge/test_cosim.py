"""The closed loop with real SUMO: every controller, outputs, refusals, interruption."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.session import prepare_run
from arzsumo.cli import main
from arzsumo.errors import ScenarioError
from arzsumo.outputs.bridge import write_results
from arzsumo.scenario import load_scenario
from tests.runs import SMALL_GRIDS, prepared

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
pytestmark = pytest.mark.sumo


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(DEFAULT)


def _short(scenario, controller, seed=42, horizon=60.0, warmup=40.0):
    return run_cosimulation(prepared(scenario, SMALL_GRIDS, controller=controller, seed=seed,
                                     horizon=horizon, warmup=warmup))


@pytest.fixture(scope="module")
def runs(scenario, tmp_path_factory, monkeypatch_module):
    monkeypatch_module.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
    out = {}
    for name in ("open", "backstepping", "etc", "observer-etc", "alinea"):
        res = _short(scenario, name)
        path, summ = write_results(res, tmp_path_factory.mktemp(name) / "run", "# test\n",
                                   plots=name in ("etc", "alinea"))
        out[name] = (res, path, summ)
    return out


@pytest.fixture(scope="module")
def monkeypatch_module():
    with pytest.MonkeyPatch.context() as mp:
        yield mp


def test_every_controller_completes_and_writes_its_outputs(runs):
    for name, (res, path, summ) in runs.items():
        assert summ["controller"] == name and summ["complete"]
        for f in ("periods.parquet", "cells.parquet", "summary.json", "scenario.toml"):
            assert (path / f).is_file(), (name, f)
        assert res.t.size == 60 and res.micro.shape == (60, 4, 20)
        assert {"plan_changes", "light_changes", "triggers", "release_time", "TTT",
                "total_delay", "J_fuel", "J_discom", "rmse", "max_ramp_queue", "inserted",
                "requested", "teleports", "collisions", "wall_time", "seed", "scenario",
                "version"} <= set(summ)
        assert summ["inserted"] + summ["waiting"] == summ["requested"]
    for name in ("etc", "alinea"):
        assert all((runs[name][1] / f).is_file() for f in ("fields_h.png", "control.png"))


def test_trigger_count_from_the_period_table_equals_the_summary(runs):
    for _name, (_res, path, summ) in runs.items():
        table = pq.read_table(path / "periods.parquet").to_pandas()
        assert int(table["triggered"].sum()) == summ["triggers"]
        assert summ["release_time"] == pytest.approx(60.0 - summ["triggers"])


def _paper_indices_from_cells(path: Path, scenario) -> dict[str, float]:
    """The section's TTT, total delay, J_fuel and J_discom (paper, section 5) recomputed
    from cells.parquet alone: the SUMO cells pivoted to (t, x), empty cells' speeds given
    the equilibrium speed at their densities, integrals by numpy's trapezoid in time."""
    from arzsumo.bridge.estimator import fill_speeds
    from arzsumo.pde.metrics import B_FUEL

    cells = pd.read_parquet(path / "cells.parquet")
    micro = cells[cells["source"] == "micro"]
    grid = {c: micro.pivot(index="t_s", columns="x_m", values=c)
            for c in ("rho_h", "v_h", "rho_a", "v_a")}
    t, x = grid["rho_h"].index.to_numpy(), grid["rho_h"].columns.to_numpy()
    f = {c: g.to_numpy() for c, g in grid.items()}
    f["v_h"], f["v_a"] = fill_speeds(scenario.params, f["rho_h"], f["v_h"], f["rho_a"],
                                     f["v_a"])
    dx, (b0, b1, b2, b3) = x[1] - x[0], B_FUEL
    out = dict.fromkeys(("TTT", "total_delay", "J_fuel", "J_discom"), 0.0)
    for rho, v, v_free in ((f["rho_h"], f["v_h"], scenario.params.v_free_h),
                           (f["rho_a"], f["v_a"], scenario.params.v_free_a)):
        a = np.gradient(v, t, axis=0) + v * np.gradient(v, x, axis=1)
        a_t = np.gradient(a, t, axis=0)
        def integral(q):
            return float(np.trapezoid(q.sum(axis=1) * dx, t))
        ttt = integral(rho)
        out["TTT"] += ttt
        out["total_delay"] += ttt - integral(rho * v) / v_free
        out["J_fuel"] += integral(np.maximum(0, b0 + b1 * v + b2 * v * a + b3 * v ** 3) * rho)
        out["J_discom"] += integral((a ** 2 + a_t ** 2) * rho)
    return out


def test_the_paper_indices_from_sumo_agree_with_a_recomputation_from_the_cells(scenario,
                                                                               runs):
    for name in ("open", "etc"):
        _res, path, summ = runs[name]
        again = _paper_indices_from_cells(path, scenario)
        assert again["TTT"] > 60.0 * 5          # the section held vehicles all along
        for key, value in again.items():
            assert summ["section"][key]["total"] == pytest.approx(value, rel=1e-9), key


def test_the_run_writes_every_column_of_its_table_in_summary_csv(runs):
    from arzsumo.bridge.compare import COLUMNS, row_of

    for _, path, summ in runs.values():
        table = pd.read_csv(path / "summary.csv")
        assert len(table) == 1
        assert list(table.columns) == list(row_of(summ))
        assert {c for c, _ in COLUMNS} <= set(table.columns)


def test_open_loop_never_touches_the_meter_and_backstepping_updates_every_period(runs):
    assert runs["open"][2]["plan_changes"] == 0
    assert np.all(runs["open"][0].periods["u"] == 0)
    assert runs["backstepping"][2]["triggers"] == 60
    assert runs["etc"][2]["triggers"] < 60
    assert runs["etc"][2]["plan_changes"] <= runs["backstepping"][2]["plan_changes"]


def test_same_seed_same_numbers(scenario, runs):
    again = _short(scenario, "etc")
    first = runs["etc"][0]
    np.testing.assert_array_equal(again.micro, first.micro)
    np.testing.assert_array_equal(again.periods["u"], first.periods["u"])


def test_free_flow_with_a_pde_controller_is_refused_before_sumo_starts(tmp_path, capsys):
    text = DEFAULT.read_text().replace(
        "[equilibrium]\nrho_h_veh_km = 80.8154\nrho_a_veh_km = 41.2363",
        "[equilibrium]\nrho_h_veh_km = 20\nrho_a_veh_km = 10")
    path = tmp_path / "free.toml"
    path.write_text(text)
    sc = load_scenario(path)
    with pytest.raises(ScenarioError, match=r"lambda_4 = .* >= 0 \(free flow\)"):
        prepare_run(sc, controller="etc")            # the one place a run is checked
    t0 = time.perf_counter()
    assert main(["run", str(path), "--quiet", "--out", str(tmp_path / "out")]) == 2
    assert time.perf_counter() - t0 < 5                  # no SUMO run happened
    assert "free flow" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_run_killed_halfway_leaves_no_complete_results(tmp_path):
    out = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "arzsumo.cli", "run", str(DEFAULT),
                             "--out", str(out), "--horizon", "300"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            start_new_session=True)
    deadline = time.time() + 60
    seen = b""
    while time.time() < deadline and b" control " not in seen:   # inside the SUMO run
        seen += proc.stderr.read1(256) if proc.stderr else b""
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    assert not out.exists()
    assert not any((p / "summary.json").exists() for p in tmp_path.iterdir() if p.is_dir())


def test_practitioner_alinea_holds_its_period_and_held_keeps_r_min(scenario):
    """One-per-green meter, 20 s ALINEA period, 80 s of control: the law's command (and,
    without [actuation] limits, the U applied) changes at most once per ALINEA period;
    the held meter asks for r_min from the first check of the window."""
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.scenario.sumo import MODE_ONLY_KEYS

    tables = dict(scenario.tables)       # the fixed cycle's keys would be refused
    tables["sumo"] = {k: v for k, v in tables["sumo"].items()
                      if k not in MODE_ONLY_KEYS["fixed_cycle"]}
    sc = scenario_from_dict(tables, scenario.source).with_(
        {"sumo.meter_mode": "one_per_green", "alinea.period_s": 20, "alinea.target_pct": 20})
    period = sc.alinea.period
    cfg = sc.sumo
    for name in ("alinea", "held"):
        res = _short(sc, name, horizon=80.0)
        per = res.periods
        assert per["occupancy_out"].size == 80 and np.isfinite(per["occupancy_out"]).all()
        assert np.nanmax(per["flow_out_loop"]) > 0          # the loop on `down` sees traffic
        if name == "alinea":
            for col in ("u_continuous", "u_raw", "u"):
                changes = per["t"][1:][np.diff(per[col]) != 0]
                counts = np.bincount((changes // period).astype(int), minlength=4)
                assert counts.max() <= 1, (col, changes)
            assert per["u"][0] == 0.0                        # nominal until a period ends
            assert res.controller_log.triggers >= 1
        else:
            np.testing.assert_allclose(per["release_rate"], cfg.release_rate_min)
            np.testing.assert_allclose(per["u"], cfg.release_rate - cfg.release_rate_min)
