"""The lateral snapshots in a real (short) run: one per control period of the window,
every vehicle on main in it, and the summary's lateral files sharing the samples."""

import json
from pathlib import Path

import numpy as np
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.outputs.bridge import write_results
from arzsumo.scenario import load_scenario
from arzsumo.sumo.network import MAIN
from arzsumo.sumo.sensor import SumoSensor
from tests.runs import prepared

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
WARMUP, HORIZON = 30.0, 40.0
pytestmark = pytest.mark.sumo


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """An open-loop run; the number of vehicles on main at every period end of the
    window, counted with libsumo independently of the sensor."""
    on_main: list[int] = []
    observe = SumoSensor.observe

    def counting(sensor: SumoSensor, t: float, pending=None):
        got = observe(sensor, t, pending)
        if got[1] is not None and sensor.window_open:
            on_main.append(int(sensor.lib.edge.getLastStepVehicleNumber(MAIN)))
        return got

    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        mp.setattr(SumoSensor, "observe", counting)
        sc = load_scenario(DEFAULT)
        res = run_cosimulation(prepared(sc, {"run.twin_cells": 40}, controller="open",
                                        warmup=WARMUP, horizon=HORIZON, seed=1))
    path, _ = write_results(res, tmp_path_factory.mktemp("run") / "open", "# t\n",
                            plots=False)
    return res, np.array(on_main), json.loads((path / "summary.json").read_text())


def test_one_snapshot_per_period_of_every_vehicle_on_main(run):
    res, on_main, _ = run
    rec = res.lateral
    assert rec.counts.size == res.t.size == round(HORIZON / res.sumo.control_period)
    assert on_main.size == rec.counts.size and on_main.min() > 10
    assert rec.counts.tolist() == on_main.tolist()
    assert rec.lat.size == rec.pos.size == rec.speed.size == rec.av.size == on_main.sum()
    assert np.all(np.abs(rec.lat) <= 3.25)                 # inside the 6.5 m lane
    assert np.all((rec.pos >= 0) & (rec.pos <= res.scenario.params.length))
    assert rec.av.any() and not rec.av.all()
    assert rec.t[0] > WARMUP and np.allclose(np.diff(rec.t), res.sumo.control_period)


def test_the_files_of_each_class_share_its_samples(run):
    res, _, summ = run
    waves = summ["section"]["waves"]
    assert waves["snapshots"] == res.t.size
    assert waves["lateral_samples"] == int(res.lateral.counts.sum())
    for c, av in (("h", False), ("a", True)):
        files = waves[c]["files"]
        assert waves[c]["file_count"] == len(files) >= 1
        assert sum(f["share"] for f in files.values()) == pytest.approx(1.0)
        assert sum(f["samples"] for f in files.values()) == int((res.lateral.av == av).sum())
        centres = [files[str(k)]["centre_m"] for k in range(len(files))]
        assert centres == sorted(centres)
    sec = summ["section"]
    assert sec["speed_spread_kmh"] == sec["speed_sd_kmh"]
    assert summ["units_by_key"]["section.waves.h.files.0.share"] == "1"
    assert "?" not in summ["units_by_key"].values()
