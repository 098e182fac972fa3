"""[twin]/[initial] scenario tables, the controller registry and ``arzsumo twin``."""

from __future__ import annotations

import json
import subprocess
import sys

import pyarrow.parquet as pq
import pytest

from arzsumo.cli import main
from arzsumo.control.base import ConstantControl
from arzsumo.control.registry import (
    REGISTRY,
    ControllerSpec,
    controller_names,
    register_controller,
)
from arzsumo.engines.twin import twin_controller
from arzsumo.errors import ScenarioError
from arzsumo.scenario import scenario_from_dict


def twin_config_from_dict(data, source="<dict>"):
    return scenario_from_dict(data, source).twin


def test_defaults_and_units():
    cfg = twin_config_from_dict({"twin": {"u_max_veh_h": 360, "horizon_s": 60,
                                          "scheme": "muscl"},
                                 "initial": {"kind": "linear", "fraction": 0.1}})
    assert cfg.solver.u_max == pytest.approx(0.1) and cfg.solver.horizon == 60.0
    assert cfg.solver.scheme == "muscl" and cfg.controller == "open"
    assert cfg.initial.kind == "linear" and cfg.initial.amplitude[0] == 0.1
    default = twin_config_from_dict({})
    assert default.initial.kind == "sinusoid" and default.solver.cells == 200


@pytest.mark.parametrize(("data", "message"), [
    ({"twin": {"cells": 2.5}}, r"s.toml: \[twin\] cells = 2.5 is not allowed: an integer"),
    ({"twin": {"scheme": "weno"}}, 'scheme = "weno" is not allowed: one of first, muscl'),
    ({"twin": {"cfl": 2}}, r"cfl = 2 is not allowed: a number in \(0, 1.0\]"),
    ({"twin": {"controller": "alinea"}}, 'controller = "alinea" is not allowed: one of'),
    ({"twin": {"horizon": 10}},
     r"unknown key 'horizon' \(did you mean 'horizon_s'\?\); allowed: cells"),
    ({"initial": {"kind": "linear", "amplitude": 0.1}}, "amplitude do.es. not apply"),
    ({"initial": {"amplitude": [0.1, 0.2]}}, "a number or a list of 4 numbers"),
    ({"initial": {"kind": "spiral"}}, r'\[initial\] kind = "spiral" is not allowed'),
    ({"twin": 3}, r"s.toml: twin = 3 is not allowed: a table \[twin\]"),
])
def test_bad_values_name_key_value_allowed(data, message):
    with pytest.raises(ScenarioError, match=message):
        twin_config_from_dict(data, "s.toml")


def test_registry_plugs_controllers_in(base_lin):
    assert {"open", "constant"} <= set(controller_names("twin"))
    assert "alinea" not in controller_names("twin")
    register_controller(ControllerSpec("test-const", lambda inp: ConstantControl(0.05),
                                       sumo=False))
    try:
        cfg = twin_config_from_dict({"twin": {"controller": "test-const"}})
        ctrl = twin_controller(cfg, base_lin)
        assert isinstance(ctrl, ConstantControl) and ctrl.u == 0.05
        with pytest.raises(ValueError, match="already registered"):
            register_controller(ControllerSpec("test-const", lambda inp: ConstantControl(0)))
        with pytest.raises(ScenarioError, match=r'\[run\] controller = "test-const" is not'):
            scenario_from_dict({"run": {"controller": "test-const"}})
    finally:
        REGISTRY.pop("test-const", None)
    with pytest.raises(ScenarioError, match="controller = 'test-const' is not allowed: one of"):
        twin_controller(cfg, base_lin)


SHORT = """
name = "short"
[model]
preset = "paper_base"
[equilibrium]
rho_h_veh_km = 110
rho_a_veh_km = 95
[twin]
cells = 60
horizon_s = 30
controller = "{controller}"
constant_u_veh_h = {u}
[initial]
amplitude = 0.02
"""


def test_cli_twin_writes_fields_summary_plots(tmp_path, capsys):
    scen = tmp_path / "short.toml"
    scen.write_text(SHORT.format(controller="constant", u=-36))
    out = tmp_path / "out"
    assert main(["twin", str(scen), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    for key in ("triggers", "release_time", "J_fuel", "J_discom", "J_TTT", "total_delay",
                "final_norm_ratio", "controller", "scenario", "version", "seed"):
        assert key in summary
    assert summary["controller"] == "constant" and summary["complete"] is True
    assert summary["triggers"] == 1 and summary["release_time"] == pytest.approx(29.0)
    assert summary["relative_to_open_loop_percent"]["total"]["J_TTT"] > 0   # U < 0 holds
    assert abs(summary["conservation"]["balance_error"]) < 1e-9
    assert json.loads((out / "summary.json").read_text()) == summary
    fields = pq.read_table(out / "fields.parquet")
    assert fields.num_rows == 31 * 60
    assert fields.column_names == ["t_s", "x_m", "rho_h", "v_h", "rho_a", "v_a"]
    control = pq.read_table(out / "control.parquet").to_pydict()
    assert len(control["t_s"]) == 30 and control["u_applied"][0] == pytest.approx(-0.01)
    for png in ("fields_h.png", "fields_a.png", "control.png"):
        assert (out / png).read_bytes()[:4] == b"\x89PNG"
    assert not list(tmp_path.glob(".*"))                  # nothing half-written left


def test_cli_twin_incomplete_run_exit_3_and_marked(tmp_path):
    scen = tmp_path / "jam.toml"
    scen.write_text(SHORT.format(controller="constant", u=-5680))    # meter closed
    out = tmp_path / "jam"
    proc = subprocess.run([sys.executable, "-m", "arzsumo.cli", "twin", str(scen), "--out",
                           str(out), "--no-plots"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 3
    assert "stopped at t = " in proc.stdout and "AO = " in proc.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is False and "x = " in summary["status"]


def test_cli_twin_bad_scenario_is_one_line(tmp_path):
    scen = tmp_path / "bad.toml"
    scen.write_text("[twin]\nscheme = 'weno'\n")
    proc = subprocess.run([sys.executable, "-m", "arzsumo.cli", "twin", str(scen)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert f"{scen}: [twin] scheme = \"weno\" is not allowed" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_pde_controllers_run_in_the_twin_with_a_design_table(tmp_path, monkeypatch):
    """backstepping updates at every check; ETC far less often; [design] reaches the ETC."""
    from arzsumo.engines.twin import run_twin

    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    base = {"model": {"preset": "paper_base"},
            "twin": {"cells": 100, "horizon_s": 120, "kernel_cells": 100},
            "initial": {"kind": "sinusoid", "amplitude": [0.02, -0.02, 0.02, -0.02],
                        "wavenumber": 2},
            "design": {"mu": 1e-3, "A": [0.02, 0.003, 0.004]}}
    sc = scenario_from_dict({k: v for k, v in base.items() if k in ("model",)})
    counts = {}
    for name in ("backstepping", "etc"):
        data = {**base, "twin": {**base["twin"], "controller": name}}
        cfg = twin_config_from_dict(data)
        assert cfg.design.mu == 1e-3
        run = run_twin(sc, cfg, baseline=False)
        counts[name] = run.triggers
    assert counts["backstepping"] == 120
    assert counts["etc"] < 0.7 * counts["backstepping"]


def test_bad_design_table_is_named():
    with pytest.raises(ScenarioError, match=r"\[design\] unknown key 'nu'"):
        twin_config_from_dict({"design": {"nu": 1.0}})
    with pytest.raises(ScenarioError, match=r"m0 = 0.5 is not allowed"):
        twin_config_from_dict({"design": {"m0": 0.5}})
