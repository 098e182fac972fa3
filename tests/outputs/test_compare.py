"""``arzsumo compare`` writes its table (from :mod:`arzsumo.bridge.compare`) and its bar plot
(from :mod:`arzsumo.plots.evaluation`) through :mod:`arzsumo.outputs.compare`."""

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


def _cells(path, t, x, v_h):
    rows = [{"source": s, "t_s": ti, "x_m": xi, "rho_h": 0.1, "v_h": v_h(ti, xi),
             "rho_a": 0.02, "v_a": 5.0} for s in ("micro", "replay") for ti in t for xi in x]
    pd.DataFrame(rows).to_parquet(path / "cells.parquet")


def test_the_fields_of_each_run_are_read_back_on_their_grid(tmp_path):
    import numpy as np

    from arzsumo.outputs.compare import micro_fields
    run = _run(tmp_path / "a", "open", 1, 0, 3600.0)
    t, x = np.array([1.0, 2.0, 3.0]), np.array([25.0, 75.0])
    _cells(run, t, x, lambda ti, xi: ti + xi / 1000.0)
    tt, xx, fields = micro_fields(run)
    np.testing.assert_array_equal(tt, t)
    np.testing.assert_array_equal(xx, x)
    assert fields.shape == (3, 4, 2)                    # (n_t, field, n_x)
    np.testing.assert_allclose(fields[:, 1, :], t[:, None] + x[None, :] / 1000.0)
    np.testing.assert_allclose(fields[:, 0, :], 0.1)


def test_runs_with_cells_on_one_grid_get_field_figures_and_others_none(tmp_path):
    eq = {"rho_h": 0.1, "v_h": 9.0, "rho_a": 0.02, "v_a": 5.0}
    runs = []
    for name, c in (("a", "open"), ("b", "backstepping")):
        run = _run(tmp_path / name, c, 1, 0, 3600.0)
        doc = json.loads((run / "summary.json").read_text())
        (run / "summary.json").write_text(json.dumps({**doc, "equilibrium": eq}))
        _cells(run, [1.0, 2.0, 3.0], [25.0, 75.0], lambda ti, xi: 8.0 + ti)
        runs.append(run)
    compare_runs(runs, tmp_path / "out")
    for cls in ("hv", "av"):
        assert (tmp_path / "out" / f"fields_{cls}.png").read_bytes()[:4] == b"\x89PNG"
    _cells(runs[1], [1.0, 2.0], [25.0, 75.0], lambda ti, xi: 8.0)   # another grid
    compare_runs(runs, tmp_path / "out")         # the same comparison, now unfit
    assert not list((tmp_path / "out").glob("fields_*.png"))
