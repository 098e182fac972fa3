"""Sensing and estimation in the closed loop: real SUMO, short runs on
``scenarios/legacy_default.toml`` (40 s warm-up, seed 42).

Measured when written (60 s of control, loops every 250 m and every AV a probe):
backstepping made 49 plan changes on the raw cells, 28 on the ASM estimate and 52 on the
EnKF's (44 before the EnKF had model-error noise); the ETC 16, 4 and 8. The EnKF's RMSE
relative to the equilibrium (backstepping) was rho_h 0.17, v_h 0.12, rho_a 0.19, v_a 0.08
against linear interpolation between the loops' 0.35, 0.12, 0.70, 0.71; its spread 0.04,
0.04, 0.06, 0.04.
"""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import numpy as np
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.cli import main
from arzsumo.outputs.bridge import VARIABLES, summary
from tests.runs import SMALL_GRIDS, prepared

pytestmark = pytest.mark.sumo

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
LOOPS = {"sensing.kinds": ["loops", "av_probes"], "sensing.loop_spacing_m": 250}


def _run(changes, controller, horizon=60.0):
    return run_cosimulation(prepared(DEFAULT, {**(changes or {}), **SMALL_GRIDS},
                                     controller=controller, warmup=40.0, horizon=horizon,
                                     seed=42))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        mp.setenv("OPENBLAS_NUM_THREADS", "1")
        out = {"raw": _run({}, "backstepping"),
               "raw+loops": _run(LOOPS, "backstepping"),
               "smoothing": _run({**LOOPS, "estimation.method": "smoothing"}, "backstepping"),
               "enkf": _run({**LOOPS, "estimation.method": "enkf"}, "backstepping")}
        for method in ("smoothing", "enkf"):
            out[f"etc {method}"] = _run({**LOOPS, "estimation.method": method}, "etc")
        return out | {"etc raw": _run({}, "etc")}


def test_method_none_acts_on_the_raw_cells_and_loops_change_nothing(runs):
    raw, loops = runs["raw"], runs["raw+loops"]
    for key in raw.periods:                     # loading the E1 stations moves no vehicle
        if key != "controller_s":
            np.testing.assert_array_equal(raw.periods[key], loops.periods[key], err_msg=key)
    np.testing.assert_array_equal(raw.micro, loops.micro)
    est = summary(raw)["estimation"]
    assert est["method"] == "none" and est["sensors"] == ["probe"]
    for name in ("rho_h", "rho_a"):             # the controller got the probe's densities
        assert est[name]["absolute"] == 0.0 and est[name]["samples"] == raw.micro[:, 0].size
    assert est["spread"] is None and est["interpolation"] is None
    assert summary(loops)["estimation"]["interpolation"]["rho_h"]["absolute"] > 0


def test_enkf_estimate_beats_interpolation_between_the_loops(runs):
    res = runs["enkf"]
    assert res.estimate.shape == res.micro.shape == (60, 4, 20)
    est = summary(res)["estimation"]
    assert est["method"] == "enkf" and est["sensors"] == ["loops", "av_probes"]
    for name in VARIABLES:
        assert math.isfinite(est[name]["absolute"]) and est[name]["samples"] > 1000
        assert 0 < est["spread"][name]["absolute"] < est[name]["absolute"]
    for name in VARIABLES:
        assert est[name]["absolute"] < est["interpolation"][name]["absolute"], name


def _plan_changes(runs, controller):
    key = "" if controller == "backstepping" else "etc "
    return tuple(summary(runs[f"{key}{m}"])["plan_changes"]
                 for m in ("raw", "smoothing", "enkf"))


@pytest.mark.parametrize(("controller", "measured"), [("backstepping", (49, 28, 52)),
                                                      ("etc", (16, 4, 8))])
def test_controllers_change_the_plan_less_often_on_the_asm_estimate(runs, controller,
                                                                    measured):
    """Same seed, same traffic until the first command: plan changes on the raw cells,
    the ASM estimate and the EnKF's (loops every 250 m + every AV a probe)."""
    raw, smooth, enkf = _plan_changes(runs, controller)
    assert (raw, smooth, enkf) == measured            # measured; below, the claim itself
    assert smooth < raw


@pytest.mark.parametrize("controller", [
    pytest.param("backstepping", marks=pytest.mark.xfail(
        strict=True, reason="with the model-error noise the EnKF's mean follows "
                            "the loops more closely and backstepping's U on it is rougher: "
                            "52 plan changes against 49 on raw cells (44 without the noise)")),
    "etc"])
def test_controllers_change_the_plan_less_often_on_the_enkf_estimate(runs, controller):
    raw, _, enkf = _plan_changes(runs, controller)
    assert enkf < raw


@pytest.mark.parametrize(("method", "paper_observer"), [("none", True), ("enkf", False)])
def test_observer_etc_uses_the_estimator_of_the_boundary_loops(method, paper_observer,
                                                               tmp_path, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    res = _run({**LOOPS, "estimation.method": method}, "observer-etc", horizon=10.0)
    assert ("y" in res.controller_log.extra) is paper_observer   # the observer's output
    est = summary(res)["estimation"]
    assert est["sensors"] == (["loops", "av_probes"] if paper_observer
                              else ["loops (boundaries)"])


def _cli(tmp_path, text, controller="etc"):
    body = DEFAULT.read_text(encoding="utf-8").replace(
        'controller = "etc"', f'controller = "{controller}"')
    path = tmp_path / "s.toml"
    path.write_text(body + text, encoding="utf-8")
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(["run", str(path), "--dry-run"])
    return code, err.getvalue()


@pytest.mark.parametrize(("text", "message"), [
    ('\n[estimation]\nmethod = "kalman"\n',
     '[estimation] method = "kalman" is not allowed: one of none, smoothing, enkf'),
    ('\n[estimation]\nmembers = 1\n', "[estimation] members = 1 is not allowed"),
    ('\n[estimation]\nasm_sigma_m = -5\n', "[estimation] asm_sigma_m = -5 is not allowed"),
    ('\n[estimation]\nloop_speed_sd_kmh = 0\n',
     "loop_speed_sd_kmh = 0 is not allowed: a standard deviation > 0 km/h"),
    ('\n[estimation]\nmembrs = 8\n', "[estimation] unknown key 'membrs'"),
    ('\n[estimation]\nmodel_sd_v_h_kmh = -1\n',
     "[estimation] model_sd_v_h_kmh = -1 is not allowed: a standard deviation >= 0 km/h"),
    ('\n[estimation]\nmethod = "enkf"\n',
     '[estimation] method = "enkf" is not allowed with [sensing] kinds = ["probe"]'),
    ('\n[sensing]\nkinds = ["av_probes"]\n[estimation]\nmethod = "enkf"\n',
     'it needs "loops"'),
    ('\n[sensing]\nkinds = ["loops"]\nloop_positions_m = [0, 500]\n[estimation]\n'
     'method = "enkf"\n', "loop_positions_m without 0 and 1000"),
])
def test_bad_estimation_keys_are_refused_in_one_line(tmp_path, text, message):
    code, err = _cli(tmp_path, text)
    assert code == 2 and err.count("\n") == 1, err
    assert err.startswith("arzsumo: error: ") and message in err, err


def test_observer_etc_on_an_estimate_needs_loops(tmp_path):
    text = '\n[sensing]\nkinds = ["av_probes"]\n[estimation]\nmethod = "smoothing"\n'
    assert _cli(tmp_path, text) == (0, "")
    code, err = _cli(tmp_path, text, controller="observer-etc")
    assert code == 2 and err.count("\n") == 1 and 'add "loops" to [sensing] kinds' in err
