"""Offline estimation on a recorded run equals the estimator inside the closed loop:
real SUMO, ``scenarios/legacy_default.toml``, 40 s warm-up + 30 s, seed 42."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from arzsumo_studies.estimation.sensor_record import (
    SensorRecord,
    record_run,
    replay_estimation,
)

from arzsumo.bridge.estimators import estimation_scores
from arzsumo.bridge.session import run_in_sumo
from arzsumo.outputs.bridge import VARIABLES, summary
from arzsumo.scenario import load_scenario

pytestmark = pytest.mark.sumo

LEGACY = Path(__file__).resolve().parents[3] / "scenarios" / "legacy_default.toml"
LAYOUT = {"sensing.kinds": ["loops", "av_probes"], "sensing.loop_spacing_m": 250}


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        mp.setenv("OPENBLAS_NUM_THREADS", "1")
        rec, info = record_run(load_scenario(LEGACY), 42, 40.0, 30.0)
        path = tmp_path_factory.mktemp("rec") / "rec.npz"
        rec.save(path, info)
        return SensorRecord.load(path)[0], rec


def test_the_record_holds_the_superset_and_survives_the_file(recorded):
    loaded, rec = recorded
    assert rec.start == 39 and rec.t.size == 70 and rec.truth().shape == (30, 4, 20)
    np.testing.assert_allclose(rec.loop_x, [6.0, *range(50, 1000, 50), 999.9])
    assert int(rec.probe_n.sum()) == rec.probe_x.size > 0
    for name in ("t", "flow", "speed", "speed_harmonic", "density", "probe_x", "samples_h"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(rec, name))
    # both means of the same spot speeds, NaN at the same places, harmonic the lower
    # (speeds under V_MIN = 0.5 m/s are floored in the harmonic mean only)
    tm, hm = rec.speed, rec.speed_harmonic
    np.testing.assert_array_equal(np.isnan(tm), np.isnan(hm))
    ok = np.isfinite(tm) & (tm >= 0.5)
    assert np.all(hm[ok] <= tm[ok] + 1e-9) and np.any(hm[ok] < tm[ok] - 0.1)


def test_a_record_without_harmonic_speeds_replays_time_mean_only(recorded, tmp_path):
    # records saved without harmonic speeds: time_mean as before, harmonic refused
    old = dataclasses.replace(recorded[1], speed_harmonic=None)
    old.save(tmp_path / "old.npz")
    loaded = SensorRecord.load(tmp_path / "old.npz")[0]
    assert loaded.speed_harmonic is None
    sc = load_scenario(LEGACY).with_(LAYOUT)
    ms = loaded.measurements(sc.sensing, sc.estimation, sc.params.length)
    assert ms[5].loops is not None and ms[5].loops.harmonic is None
    np.testing.assert_array_equal(ms[5].loops.speed, recorded[1].speed[5][:, ::5])
    harmonic = load_scenario(LEGACY).with_({**LAYOUT, "sensing.loop_speed": "harmonic"})
    with pytest.raises(ValueError, match="no harmonic loop speeds"):
        loaded.measurements(harmonic.sensing, harmonic.estimation, sc.params.length)
    ms = recorded[1].measurements(harmonic.sensing, harmonic.estimation, sc.params.length)
    np.testing.assert_array_equal(ms[5].loops.speed, recorded[1].speed_harmonic[5][:, ::5])


@pytest.mark.parametrize(("method", "loop_speed"), [
    ("smoothing", "time_mean"), ("enkf", "time_mean"), ("smoothing", "harmonic")])
def test_offline_estimation_equals_the_closed_loop(recorded, method, loop_speed, tmp_path,
                                                   monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    rec = recorded[0]
    sc = load_scenario(LEGACY).with_({**LAYOUT, "estimation.method": method,
                                      "sensing.loop_speed": loop_speed,
                                      "run.controller": "open"})
    online = summary(run_in_sumo(sc, seed=42, horizon=30.0, warmup=40.0).result)
    offline = estimation_scores(rec.truth(), replay_estimation(rec, sc), sc.equilibrium)
    on = online["estimation"]
    for name in VARIABLES:
        assert on[name]["samples"] == offline[name]["samples"] > 500
        assert offline[name]["absolute"] == pytest.approx(on[name]["absolute"], abs=1e-9)
        assert offline["interpolation"][name]["absolute"] == pytest.approx(
            on["interpolation"][name]["absolute"], abs=1e-9)
    assert (offline["spread"] is None) is (method == "smoothing")
    loops = "loops (harmonic speed)" if loop_speed == "harmonic" else "loops"
    assert on["sensors"] == offline["sensors"] == [loops, "av_probes"]


def test_a_layout_with_stations_not_recorded_is_refused(recorded):
    sc = load_scenario(LEGACY).with_({"sensing.kinds": ["loops"],
                                      "sensing.loop_spacing_m": 120})
    with pytest.raises(ValueError, match="not all among the recorded"):
        recorded[0].stations(sc.sensing, sc.params.length)
