"""``arzsumo twin``: which controller runs (flag, [twin], [run], default) and the printed
indices in veh h with their units."""

from __future__ import annotations

import json

import pytest

from arzsumo.api.runs import twin_controller as twin_controller_of
from arzsumo.cli import main
from arzsumo.scenario import scenario_from_dict

BASE = {"model": {"preset": "paper_base"},
        "equilibrium": {"rho_h_veh_km": 110, "rho_a_veh_km": 95},
        "twin": {"cells": 40, "horizon_s": 30, "kernel_cells": 40},
        "initial": {"amplitude": 0.02}}


def _scenario(twin: dict | None = None, run: dict | None = None):
    data = {**BASE, "twin": {**BASE["twin"], **(twin or {})}}
    if run is not None:
        data["run"] = run
    return scenario_from_dict(data, "s.toml")


@pytest.mark.parametrize(("twin", "run", "flag", "name", "origin"), [
    ({}, {"controller": "etc"}, None, "etc", "[run] controller"),
    ({"controller": "backstepping"}, {"controller": "etc"}, None, "backstepping",
     "[twin] controller"),
    ({"controller": "backstepping"}, {"controller": "etc"}, "open", "open", "--controller"),
    ({}, None, None, "open", "the default"),
    ({}, {"controller": "alinea"}, None, "open",
     "the default; [run] controller = alinea does not run in the twin"),
])
def test_the_controller_and_where_it_came_from(twin, run, flag, name, origin):
    sc, said = twin_controller_of(_scenario(twin, run), flag)
    assert sc.twin.controller == name and said == origin


def test_twin_runs_the_run_controller_and_prints_veh_h(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path / "cache"))
    path = tmp_path / "short.toml"
    path.write_text("""[model]
preset = "paper_base"
[equilibrium]
rho_h_veh_km = 110
rho_a_veh_km = 95
[twin]
cells = 40
horizon_s = 30
kernel_cells = 40
[initial]
amplitude = 0.02
[run]
controller = "etc"
""")
    assert main(["twin", str(path), "--out", str(tmp_path / "o"), "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].startswith("twin short: controller etc (from [run] controller)")
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["controller"] == "etc"
    ttt = next(line for line in out.splitlines() if line.startswith("  J_TTT (veh h)"))
    assert float(ttt.split("total")[1].split()[0]) == pytest.approx(
        summary["J_TTT"]["total"] / 3600, rel=1e-3)
    for head in ("  total delay (veh h)", "  J_fuel (veh)",
                 "  J_discom (veh m^2/s^3 + veh m^2/s^5)", "  vehicles (veh)"):
        assert any(line.startswith(head) for line in out.splitlines()), head
    assert main(["twin", str(path), "--controller", "open", "--out", str(tmp_path / "p"),
                 "--no-plots"]) == 0
    assert "controller open (from --controller)" in capsys.readouterr().out
