"""``arzsumo compare`` writes its table (from :mod:`arzsumo.bridge.compare`) and its bar plot
(from :mod:`arzsumo.plots.compare`) through :mod:`arzsumo.outputs.compare`."""

from __future__ import annotations

import json

import pandas as pd

from arzsumo.outputs.compare import compare_runs


def _run(path, controller, seed, plan_changes, ttt_s):
    path.mkdir()
    summ = {"kind": "run", "scenario": "s", "horizon": 60.0, "warmup": {"duration_s": 30.0},
            "controller": controller, "seed": seed, "plan_changes": plan_changes,
            "light_changes": 2 * plan_changes, "triggers": 3, "release_time": 40.0,
            "TTT": {"total": ttt_s}, "total_delay": {"total": 360.0},
            "speed_variance": {"h": 4.0, "a": 1.0}}
    (path / "summary.json").write_text(json.dumps(summ), encoding="utf-8")
    return path


def test_compare_writes_the_table_and_the_figure(tmp_path):
    runs = [_run(tmp_path / "a", "etc", 1, 4, 7200.0), _run(tmp_path / "b", "etc", 2, 6, 3600.0),
            _run(tmp_path / "c", "open", 1, 0, 10800.0)]
    text, csv, png = compare_runs(runs, tmp_path / "out")
    df = pd.read_csv(csv)
    assert df["controller"].tolist() == ["etc", "etc", "open"]
    assert df["TTT_veh_h"].tolist() == [2.0, 1.0, 3.0]            # s -> veh h
    assert df["speed_sd_h_kmh"].tolist() == [7.2, 7.2, 7.2]       # sqrt(4) m/s in km/h
    assert png.stat().st_size > 5_000
    assert "plan chg" in text and "open" in text
