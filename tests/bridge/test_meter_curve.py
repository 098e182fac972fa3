"""``[sumo] meter_curve``: a calibrated meter curve reaches ``arzsumo run`` and sweeps."""

import json
import tomllib
from pathlib import Path

import pytest

import arzsumo.bridge.session as session
from arzsumo.cli import main
from arzsumo.resources import default_scenario
from arzsumo.sumo.calibration_io import curve_text, load_green_share_curve
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE, GreenShareCurve
from arzsumo.sweep.spec import sweep_from_dict
from arzsumo.units import veh_h_to_veh_s

#: a curve unlike DEFAULT_CURVE: 4000 veh/h at the nominal green share 0.5 (default 4464)
CURVE = GreenShareCurve((0.0, 0.5, 1.0), tuple(veh_h_to_veh_s(q) for q in (5000, 4000, 3000)))


def _scenario(tmp_path: Path, meter_curve: str | None, curve: bool = True) -> Path:
    """legacy_default, short, in ``tmp_path/sc/``, with its curve in ``sc/cal/``."""
    text = (default_scenario().parent / "legacy_default.toml").read_text(encoding="utf-8")
    text = text.replace("warmup_s = 150", "warmup_s = 20")
    text = text.replace("kernel_cells = 100", "kernel_cells = 50")
    text = text.replace("twin_cells = 100", "twin_cells = 50")
    if meter_curve is not None:
        text = text.replace("[sumo]\n", f'[sumo]\nmeter_curve = "{meter_curve}"\n')
    (tmp_path / "sc" / "cal").mkdir(parents=True)
    if curve:
        (tmp_path / "sc" / "cal" / "meter_curve.toml").write_text(
            curve_text(CURVE, SumoConfig()), encoding="utf-8")
    path = tmp_path / "sc" / "curved.toml"
    path.write_text(text, encoding="utf-8")
    assert tomllib.loads(text)["run"]["warmup_s"] == 20
    return path


@pytest.mark.sumo
def test_run_uses_the_scenarios_meter_curve(tmp_path, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path / "cache"))
    monkeypatch.chdir(tmp_path)  # the curve is found relative to the scenario, not here
    path = _scenario(tmp_path, "cal/meter_curve.toml")
    out = tmp_path / "out"
    assert main(["run", str(path), "--horizon", "20", "--quiet", "--no-plots",
                 "--out", str(out)]) == 0
    summ = json.loads((out / "summary.json").read_text())
    loaded = load_green_share_curve(tmp_path / "sc" / "cal" / "meter_curve.toml")
    assert summ["q_nominal"] == pytest.approx(loaded.outflow_at(0.5))
    assert summ["q_nominal"] == pytest.approx(4000 / 3600, rel=1e-6)
    assert summ["q_nominal"] != pytest.approx(DEFAULT_CURVE.outflow_at(0.5))
    resolved = (tmp_path / "sc" / "cal" / "meter_curve.toml").resolve()
    assert f"meter_curve='{resolved}'" in (out / "scenario.toml").read_text()


@pytest.mark.parametrize(("written", "curve"), [("cal/nope.toml", True),
                                                ("cal/meter_curve.toml", False)])
def test_a_missing_curve_file_is_refused_before_sumo_starts(tmp_path, monkeypatch, capsys,
                                                            written, curve):
    def no_sumo(*args, **kwargs):
        raise AssertionError("SUMO started")

    monkeypatch.setattr(session, "run_cosimulation", no_sumo)
    path = _scenario(tmp_path, written, curve=curve)
    out = tmp_path / "out"
    assert main(["run", str(path), "--quiet", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert err.startswith(f'arzsumo: error: {path}: [sumo] meter_curve = "{written}" is not '
                          "allowed: there is no file")
    assert "relative to the scenario file" in err
    assert not out.exists()


def test_a_bad_curve_file_names_the_scenario_and_the_key(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(session, "run_cosimulation", lambda *a, **k: pytest.fail("SUMO"))
    path = _scenario(tmp_path, "cal/meter_curve.toml")
    (tmp_path / "sc" / "cal" / "meter_curve.toml").write_text(
        "green_share = [0.0, 1.0]\noutflow_veh_h = 4000\n", encoding="utf-8")
    assert main(["run", str(path), "--quiet", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"arzsumo: error: {path}: [sumo] meter_curve: ")
    assert "outflow_veh_h = 4000 is not allowed: a list of numbers" in err


def test_sweeps_read_the_curve_relative_to_the_file_that_names_it(tmp_path):
    base = _scenario(tmp_path, "cal/meter_curve.toml")
    (tmp_path / "other.toml").write_text(curve_text(CURVE, SumoConfig()), encoding="utf-8")
    data = {"base": "sc/curved.toml", "engine": "sumo", "seeds": [1],
            "axis": [{"field": "sumo.meter_curve", "values": ["", "other.toml"]}]}
    spec = sweep_from_dict(data, "s.toml", root=tmp_path)
    assert spec.base == base
    curves = [r.scenario["sumo"]["meter_curve"] for r in spec.runs()]
    assert curves == ["", str(tmp_path / "other.toml")]
    assert spec.base_data["sumo"]["meter_curve"] == str(base.parent / "cal/meter_curve.toml")
