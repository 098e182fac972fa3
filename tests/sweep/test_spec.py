"""Sweep files: expansion into runs, stable IDs, one-at-a-time groups, errors."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from arzsumo.scenario import scenario_from_dict
from arzsumo.sweep import SweepError, load_sweep, sweep_from_dict

ROOT = Path(__file__).resolve().parents[2]
BASE = "scenarios/paper/penetration_44_etc.toml"


def spec_of(**data):
    return sweep_from_dict({"base": BASE, **data}, "test.toml", root=ROOT)


def test_product_order_ids_and_resolved_scenarios():
    spec = spec_of(engine="twin", seeds=[1, 2], set={"initial": {"kind": "random"},
                                                     "twin.cells": 50},
                   axis=[{"field": "equilibrium.penetration", "values": [0.44, 0.5, 0.53]}])
    runs = spec.runs()
    assert [r.run_id for r in runs] == [f"penetration={p},seed={s}" for p in (0.44, 0.5, 0.53)
                                        for s in (1, 2)]
    assert [r.index for r in runs] == list(range(6))
    r = runs[3]
    assert dict(r.columns) == {"penetration": 0.5, "seed": 2}
    assert r.scenario["equilibrium"]["penetration"] == 0.5
    assert r.scenario["twin"] == {**spec.base_data["twin"], "cells": 50, "seed": 2}
    assert r.scenario["initial"]["kind"] == "random"
    assert spec.base_data["twin"]["cells"] == 200          # the base is not modified
    # every resolved scenario is a valid scenario, and the seed reaches the random wave
    cfg = scenario_from_dict(r.scenario, "run").twin
    assert cfg.seed == 2 and cfg.initial.seed == 2 and cfg.initial.kind == "random"
    assert scenario_from_dict(r.scenario).equilibrium.penetration == pytest.approx(0.5)
    assert len({x.sha256 for x in runs}) == 6


def test_ids_and_fingerprints_do_not_depend_on_order():
    axis = {"field": "equilibrium.penetration", "values": [0.44, 0.5, 0.53]}
    a = {r.run_id: r.sha256 for r in spec_of(seeds=[1, 2], axis=[axis]).runs()}
    b = {r.run_id: r.sha256 for r in spec_of(seeds=[2, 1], axis=[
        {**axis, "values": [0.53, 0.44, 0.5]}]).runs()}
    assert a == b
    changed = spec_of(seeds=[1, 2], axis=[axis], set={"twin.horizon_s": 100}).runs()
    assert all(a[r.run_id] != r.sha256 for r in changed)       # stale after an edit


def test_one_at_a_time_group_and_multi_field_axis():
    spec = spec_of(engine="twin", seeds=[7], axis=[
        {"name": "demand_veh_h", "values": [4966, 6510],
         "set": [{"equilibrium": {"demand_h_veh_h": 3461, "demand_a_veh_h": 1505}},
                 {"equilibrium.demand_h_veh_h": 4555, "equilibrium.demand_a_veh_h": 1955}]},
        {"field": "design.mu", "values": [1e-4, 5e-3], "group": "parameter"},
        {"field": "design.sigma", "values": [1e-5, 1e-3], "group": "parameter"},
        {"field": "twin.cells", "values": [100, 150], "group": "parameter"}])
    runs = spec.runs()
    assert len(runs) == 2 * 6
    r = next(x for x in runs if x.run_id == "demand_veh_h=6510,sigma=0.001,seed=7")
    assert r.columns == {"demand_veh_h": 6510, "parameter": "sigma", "mu": None,
                         "sigma": 1e-3, "cells": 200, "seed": 7}
    assert r.scenario["design"] == {"sigma": 1e-3}
    assert r.scenario["equilibrium"]["demand_h_veh_h"] == 4555
    assert r.scenario["twin"]["cells"] == 200                 # other group members at base


@pytest.mark.parametrize(("data", "match"), [
    ({"axis": [{"field": "equilibrium.penetrat", "values": [0.4]}]},
     r"field 'equilibrium.penetrat' is not allowed: \[equilibrium\] has branch"),
    ({"axis": [{"field": "traffic.x", "values": [1]}]},
     r"field 'traffic.x' is not allowed: 'table.key' with table one of actuation, alinea, design"),
    ({"axis": [{"field": "design.mu", "values": [1e-3, 0.001]}]}, "values repeat 0.001"),
    ({"axis": [{"field": "design.mu", "values": [1], "set": [{}]}]}, "give either field"),
    ({"axis": [{"name": "d", "values": [1, 2], "set": [{}]}]}, "set must be a list of 2"),
    ({"axis": [{"field": "design.mu", "values": []}]}, r"values = \[\] is not allowed"),
    ({"axis": [{"field": "initial.amplitude", "values": [[0.1]]}]},
     r"value \[0.1\] is not allowed: a number, string or boolean"),
    ({"engine": "vissim"}, 'engine = "vissim" is not allowed: one of twin, sumo'),
    ({"seeds": [1, -1]}, r"seeds = \[1, -1\] is not allowed"),
    ({"seeds": 0}, r"seeds = 0 is not allowed: a count N >= 1 \(seeds 1..N\)"),
    ({"seeds": True}, r"seeds = true is not allowed"),
    ({"sets": {}}, "unknown key 'sets'"),
    ({"base": 3}, r"base = 3 is not allowed: a path \(a string\)"),
    ({"description": ["x"]}, r'description = \["x"\] is not allowed: a string'),
    ({"paper": "table9"}, 'paper = "table9" is not allowed'),
    ({"base": "nope.toml"}, "base = '.*nope.toml' does not exist"),
    ({"base": "scenarios"}, "base = '.*scenarios' cannot be read"),
    ({"seeds": [1], "axis": [{"field": "twin.seed", "values": [1, 2]}]},
     "repeated: seed"),
])
def test_bad_sweep_files_name_the_key_and_value(data, match):
    with pytest.raises(SweepError, match=match):
        spec_of(**data)


def test_a_count_of_seeds_means_seeds_one_to_n():
    spec = spec_of(seeds=50)
    assert [dict(r.columns)["seed"] for r in spec.runs()] == list(range(1, 51))


def test_shipped_sweep_files_load_and_expand():
    files = sorted((ROOT / "scenarios" / "sweeps").glob("*.toml"))
    names = {f.stem for f in files}
    for study in ("penetration", "demand", "sensitivity"):
        assert {f"{study}_twin", f"{study}_sumo"} <= names
    for f in files:
        spec = load_sweep(f)
        runs = spec.runs()
        assert len(runs) >= 6 and spec.replicate == "seed"
        assert tomllib.loads(f.read_text())["engine"] == spec.engine
        scenario_from_dict(runs[0].scenario, f"{f} first run")   # the resolved runs load


def test_cli_user_errors_are_one_line_with_exit_2(tmp_path, capsys):
    from arzsumo.cli import main

    assert main(["sweep", str(tmp_path / "nope.toml")]) == 2
    assert "sweep = " in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text(f'base = "{ROOT / BASE}"\n[[axis]]\nfield = "design.muu"\nvalues = [1]\n')
    assert main(["sweep", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "field 'design.muu' is not allowed" in err
    good = tmp_path / "good.toml"
    good.write_text(f'base = "{ROOT / BASE}"\nseeds = [1, 2]\n')
    assert main(["sweep", str(good), "--workers", "0", "--out", str(tmp_path / "o")]) == 2
    assert "--workers = 0 is not allowed" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()                       # nothing half-written
    assert main(["sweep", str(good), "--list"]) == 0
    assert capsys.readouterr().out.split() == ["seed=1", "seed=2"]


def test_a_fingerprint_ignores_what_the_runs_controller_does_not_read():
    from arzsumo.sweep.spec import RunSpec

    def fp(controller: str, engine: str = "sumo", **tables) -> str:
        scenario = {"name": "a", "run": {"controller": controller, "warmup_s": 600},
                    "alinea": {"target_pct": 42.8}, **tables}
        return RunSpec("x", 0, {}, {}, scenario, engine, False).sha256

    retuned = {"alinea": {"target_pct": 50.1}}
    assert fp("open") == fp("open", **retuned)
    assert fp("etc") == fp("etc", **retuned)
    assert fp("alinea") != fp("alinea", **retuned)          # ALINEA reads its gains
    assert fp("open") == fp("open", name="b", description="another label")
    rate = {"run": {"controller": "open", "warmup_s": 600, "constant_release_veh_h": 480}}
    assert fp("open") == fp("open", **rate)
    assert fp("open", **{"run": {"controller": "open", "warmup_s": 300}}) != fp("open")
    assert fp("open", engine="twin") != fp("open", engine="twin", **retuned)
