"""The approach and fill studies: their designs, the stationarity measures, and the map
drawn from a table."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.sumo_map import approach, fill, open_loop


def test_the_maps_design_is_demand_x_green_share_without_a_fill():
    runs = approach.design(approach.ApproachOptions(demands=(4400, 5664), greens=(0.3, 0.9),
                                                    sigmas=(0.5,), seeds=(1, 2)))
    assert len(runs) == 8
    assert runs[0].run_id == "demand_veh_h=4400,green_share=0.3,hv_sigma=0.5,seed=1"
    sumo = runs[-1].scenario["sumo"]
    assert sumo["demand_h_veh_h"] + sumo["demand_a_veh_h"] == pytest.approx(5664.0)
    assert sumo["demand_a_veh_h"] == pytest.approx(1560.0)
    assert (sumo["green_share"], sumo["seed"], sumo["fill_s"], sumo["approach_length_m"],
            sumo["horizon_s"]) == (0.9, 2, 0.0, 1500.0, 450.0)
    assert runs[-1].scenario["run"]["warmup_s"] == 150.0
    assert runs[0].options["initial"] is True
    assert len(approach.design(approach.ApproachOptions(
        demands=(4400, 4800, 5200, 5664, 6000), greens=(0.3, 0.5, 0.7, 0.9), sigmas=(0.5,),
        seeds=(1,)))) == 20


def test_the_fill_design_holds_each_demand_after_the_defaults_fill():
    runs = fill.design(fill.FillOptions(holds=("3750:850", "3900:950"), seeds=(1, 2, 3)))
    assert [r.run_id for r in runs][:2] == ["hold=3750_850,green_share=0.5,hv_sigma=0.5,seed=1",
                                            "hold=3750_850,green_share=0.5,hv_sigma=0.5,seed=2"]
    sumo = runs[3].scenario["sumo"]
    assert (sumo["demand_h_veh_h"], sumo["demand_a_veh_h"], sumo["fill_demand_h_veh_h"],
            sumo["fill_demand_a_veh_h"], sumo["fill_s"]) == (3900.0, 950.0, 4200.0, 1300.0,
                                                             600.0)
    with pytest.raises(StudyError, match="'3900' is not allowed: HV:AV"):
        fill.hold_pair("3900")


def test_the_fill_study_takes_its_options_from_python_and_refuses_a_bad_one():
    """Library code: FillOptions (checked on construction) in, the design out; the
    command line builds the same options."""
    import argparse
    from pathlib import Path

    from arzsumo_studies.cli import fill as cli

    opts = fill.FillOptions(holds=("3750:850", "3900:950"), greens=(0.4, 0.6), seeds=(2,),
                            fill_s=300.0)
    runs = fill.design(opts)
    assert len(runs) == 4 and runs[0].options["fill_s"] == 300.0
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--holds", "3750:850", "3900:950", "--greens",
                                          "0.4,0.6", "--seeds", "2", "--fill", "300"])) == opts
    with pytest.raises(StudyError, match="'3900' is not allowed: HV:AV"):
        fill.FillOptions(holds=("3900",))
    with pytest.raises(StudyError, match=r"step_s = 0\.0 is not allowed: a finite number > 0"):
        fill.FillOptions(step_s=0.0)
    assert "argparse" not in Path(fill.__file__).read_text(encoding="utf-8")


def test_the_trend_of_a_linear_count_is_its_slope():
    t = np.arange(450.0)
    out = open_loop.trend(100.0 + 0.5 * t / 60.0, 1.0)     # +0.5 veh/min
    assert out["slope_veh_min"] == pytest.approx(0.5)
    assert out["slope_lo"] < 0.5 < out["slope_hi"] or out["slope_lo"] == pytest.approx(0.5)
    assert out["kendall_p"] < 1e-3
    assert out["drift_rel"] == pytest.approx(0.5 * 7.5 / out["n_mean"])
    flat = open_loop.trend(100.0 + np.random.default_rng(3).normal(0.0, 2.0, t.size), 1.0)
    assert abs(flat["drift_rel"]) < 0.01 and flat["kendall_p"] > 0.05


def test_the_regime_follows_the_sign_of_lambda_4():
    from arzsumo.scenario import load_scenario

    params = load_scenario(approach.shipped_scenario("lateral_files.toml")).params
    lam, regime = open_loop.regime(params, 93.46, 47.08)     # the former default's
    assert regime == "congested" and lam == pytest.approx(-11.2, abs=0.2)
    assert open_loop.regime(params, 10.0, 5.0)[1] == "free"


def _map_rows() -> pd.DataFrame:
    rows = []
    for d in (4400.0, 5664.0):
        for g in (0.3, 0.9):
            for seed in (1, 2):
                good = d == 5664.0 and g == 0.3
                rows.append({"demand_veh_h": d, "green_share": g, "hv_sigma": 0.5,
                             "seed": seed, "approach_m": 1500.0, "step_s": 0.1,
                             "warmup_s": 150.0, "av_share": 0.2754, "stationary": int(good),
                             "lambda4_kmh": -10.0 if good else 5.0, "sd_v_h_kmh": 12.0,
                             "inserted_main": 0.99, "slope_veh_min": 0.1 * seed,
                             "drift_rel": 0.01, "queue_m_end": 300.0})
    return pd.DataFrame(rows)


def test_points_qualify_on_every_criterion():
    means = approach.point_means(_map_rows())
    assert means["seeds"].tolist() == [2, 2, 2, 2]
    assert means[means["qualifies"]][["demand_veh_h", "green_share"]].values.tolist() == \
        [[5664.0, 0.3]]


def test_the_map_is_drawn_from_a_table(run_study, tmp_path, capsys):
    path = tmp_path / "old.csv"
    _map_rows().drop(columns="av_share").to_csv(path, index=False)   # an older table
    assert run_study("approach", "--from", path, "--out", tmp_path / "out") == 0
    assert (tmp_path / "out" / "map.png").stat().st_size > 20_000
    assert len(pd.read_csv(tmp_path / "out" / "map.csv")) == 8
    assert capsys.readouterr().out.strip() == (
        "8 runs; 1 of 4 points of the largest group qualify (stationary, congested, "
        "stop-and-go, inserted): 5664 veh/h at green 0.3")


def test_list_with_a_table_lists_no_runs_and_draws_nothing(run_study, tmp_path, capsys):
    path = tmp_path / "old.csv"
    _map_rows().to_csv(path, index=False)
    assert run_study("approach", "--from", path, "--list", "--out", tmp_path / "out") == 0
    assert capsys.readouterr().out == f"no runs: --from {path} is read instead\n"
    assert not (tmp_path / "out").exists()


def test_a_rerun_without_plots_leaves_no_map_of_the_earlier_table(run_study, tmp_path):
    path, out = tmp_path / "old.csv", tmp_path / "out"
    _map_rows().to_csv(path, index=False)
    assert run_study("approach", "--from", path, "--out", out) == 0
    assert (out / "map.png").is_file()
    _map_rows().head(4).to_csv(path, index=False)
    assert run_study("approach", "--from", path, "--out", out, "--no-plots") == 0
    assert len(pd.read_csv(out / "map.csv")) == 4 and not (out / "map.png").exists()


def test_the_approach_map_is_drawn_from_python_with_its_options(tmp_path):
    """Library code: ApproachOptions in (a table read instead of SUMO), ApproachResult
    out; the command line builds the same options, and a bad share names its field."""
    import argparse

    from arzsumo_studies.cli import approach as cli

    path = tmp_path / "old.csv"
    _map_rows().to_csv(path, index=False)
    opts = approach.ApproachOptions(source=path, out=tmp_path / "out", plots=False)
    result = approach.run_approach(opts)
    assert (len(result.table), len(result.points), result.qualify) == (8, 4, 1)
    assert result.files == (tmp_path / "out" / "map.csv",)
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--from", str(path), "--out", str(tmp_path / "out"),
                                          "--no-plots"])) == opts
    assert not cli.options(parser.parse_args(["--empty-start"])).initial
    with pytest.raises(StudyError, match=r"av_share = 1\.5 is not allowed: a number in"):
        approach.ApproachOptions(av_share=1.5)
