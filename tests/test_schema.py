"""Every Parquet column arzsumo writes states its unit; summaries give their keys' units;
docs/outputs.md describes every column and summary key."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from arzsumo.cli import main
from arzsumo.schema import (
    CELLS,
    IDENTIFY_SUMMARY,
    PERIODS,
    RUN_SUMMARY,
    SWEEP_FIXED,
    TWIN_CONTROL,
    TWIN_FIELDS,
    TWIN_SUMMARY,
    markdown,
    with_units,
)
from arzsumo.sweep import run_sweep, sweep_from_dict
from arzsumo.sweep.table import flatten, table_columns
from arzsumo.version import __version__
from tests.twin.test_config_cli import SHORT

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "outputs.md"


def units_of(table: pa.Table) -> dict[str, str]:
    """Column -> unit of a table written by arzsumo ("" where none is stored)."""
    return {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in table.schema}


def _assert_all_units(table: pa.Table) -> dict[str, str]:
    units = units_of(table)
    assert units and all(u and u != "?" for u in units.values()), units
    meta = table.schema.metadata
    assert meta[b"arzsumo.version"] == __version__.encode() and b"arzsumo.units" in meta
    return units


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A short closed loop in SUMO (ETC), written as ``arzsumo run`` writes it."""

    from arzsumo.bridge.cosim import run_cosimulation
    from arzsumo.outputs.bridge import write_results
    from tests.runs import LEGACY, prepared

    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        run = prepared(LEGACY, {"run.kernel_cells": 40, "run.twin_cells": 40},
                       controller="etc", warmup=20.0, horizon=20.0, seed=3)
        res = run_cosimulation(run)
        path, summ = write_results(res, tmp_path_factory.mktemp("run") / "run", "# t\n",
                                   plots=False)
    return path, summ


@pytest.mark.sumo
def test_run_tables_and_summary_state_units(run_dir):
    path, summ = run_dir
    periods = pq.read_table(path / "periods.parquet")
    cells = pq.read_table(path / "cells.parquet")
    pu, cu = _assert_all_units(periods), _assert_all_units(cells)
    assert pu["u"] == "veh/s" and pu["inflow_h"] == "veh/s" and pu["t_s"] == "s"
    assert pu["occupancy_out"] == "1" and pu["light_changes"] == "count"
    assert cu["rho_h"] == "veh/m" and cu["v_a"] == "m/s" and cu["x_m"] == "m"
    field = cells.schema.field("rho_h")
    assert field.metadata[b"description"].startswith(b"HV density")
    doc = json.loads((path / "summary.json").read_text())
    units = doc["units_by_key"]
    assert units == summ["units_by_key"] and "?" not in units.values()
    assert units["J_fuel.total"] == "veh" and units["TTT.h"] == "veh*s"
    assert units["twin_replay.J_discom.a"] == "veh m^2/s^3 + veh m^2/s^5"
    assert units["rmse.replay.rho_h.absolute"] == "veh/m"
    assert units["rmse.reference.v_a.absolute"] == "m/s"
    assert doc["units"] == "SI: veh, s, m; U and flows in veh/s"     # kept as it was
    # a sweep in SUMO tabulates these summaries: every column of it has a unit too
    row = {k: [v] for k, v in flatten(doc).items()}
    cols = table_columns(pd.DataFrame(row))
    assert {c: u for c, (u, _) in cols.items() if u == "?"} == {}


def test_twin_tables_and_summary_state_units(tmp_path):
    scen = tmp_path / "short.toml"
    scen.write_text(SHORT.format(controller="constant", u=-36))
    out = tmp_path / "out"
    assert main(["twin", str(scen), "--out", str(out), "--no-plots"]) == 0
    fu = _assert_all_units(pq.read_table(out / "fields.parquet"))
    cu = _assert_all_units(pq.read_table(out / "control.parquet"))
    assert fu["rho_a"] == "veh/m" and fu["v_h"] == "m/s" and cu["u_applied"] == "veh/s"
    doc = json.loads((out / "summary.json").read_text())
    units = doc["units_by_key"]
    assert "?" not in units.values()
    assert units["J_TTT.total"] == "veh*s" and units["TMT.h"] == "veh*m"
    assert units["relative_to_open_loop_percent.total.J_fuel"] == "%"
    assert units["conservation.inflow"] == "veh" and units["release_time"] == "s"
    assert doc["units"] == "SI: veh, s, m; U in veh/s"


def test_sweep_table_states_every_unit(tmp_path, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path / "cache"))
    data = {"name": "units", "base": "scenarios/paper/penetration_44_etc.toml",
            "engine": "twin", "seeds": [1],
            "set": {"initial": {"kind": "random"}, "twin": {"cells": 40, "horizon_s": 20,
                                                            "kernel_cells": 40}},
            "axis": [{"field": "equilibrium.penetration", "values": [0.44]},
                     {"field": "sumo.demand_h_veh_h", "values": [4000]}]}
    spec = sweep_from_dict(data, "units.toml", root=ROOT)
    rep = run_sweep(spec, tmp_path / "out", workers=1, progress=False, plots=False)
    assert rep.statuses == {"ok": 1}
    table = pq.read_table(tmp_path / "out" / "summaries.parquet")
    units = _assert_all_units(table)
    assert units["penetration"] == "1" and units["demand_h_veh_h"] == "veh/h"
    assert units["seed"] == "-" and units["status"] == "-"
    assert units["J_fuel.total"] == "veh" and units["final_time"] == "s"
    assert "units_by_key.J_fuel.h" not in units          # the mapping is not a column
    assert pd.read_parquet(tmp_path / "out" / "summaries.parquet").shape[0] == 1


def test_a_column_without_unit_is_refused():
    with pytest.raises(KeyError, match=r"periods: columns \['new'\] have no unit"):
        with_units(pa.table({"t_s": [0.0], "new": [1.0]}), PERIODS, "periods")


@pytest.mark.parametrize(("name", "columns"), [
    ("periods", PERIODS), ("cells", CELLS), ("fields", TWIN_FIELDS),
    ("control", TWIN_CONTROL), ("summaries", SWEEP_FIXED)])
def test_docs_list_every_column_with_the_schema_units(name, columns):
    text = DOC.read_text(encoding="utf-8")
    block = re.search(rf"<!-- schema:{name} -->\n(.*?)\n<!-- /schema -->", text, re.S)
    assert block, f"docs/outputs.md has no generated table for {name}"
    assert block.group(1) == markdown(columns)


@pytest.mark.parametrize("table", [RUN_SUMMARY, TWIN_SUMMARY, IDENTIFY_SUMMARY])
def test_docs_give_every_summary_key(table):
    text = DOC.read_text(encoding="utf-8")
    for pattern, unit in table.items():
        if unit != "-":
            assert f"`{pattern}` | {unit} |" in text, pattern


def test_the_docs_example_opens_the_directory_make_run_writes():
    from arzsumo.bridge.session import default_run_name
    from arzsumo.scenario import load_scenario

    root = Path(__file__).resolve().parents[1]
    sc = load_scenario(root / "scenarios" / "default.toml")
    (opened,) = re.findall(r'pq\.read_table\("results/([^/]+)/periods\.parquet"\)',
                           DOC.read_text(encoding="utf-8"))
    assert opened == default_run_name(sc, sc.run, sc.sumo)
