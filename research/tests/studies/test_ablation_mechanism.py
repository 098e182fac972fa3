"""The mechanism of the ablation, end to end on a made-up ablation directory: rows per
run, pairs with the right open loop, the fit at equal mean speed, the figures."""

from __future__ import annotations

import json

import pandas as pd
import pytest
from arzsumo_studies.ablation import mechanism as mech
from arzsumo_studies.common import StudyError


def _run(root, step, controller, seed, outflow, mean_h, sd_h, mean_a=14.0, sd_a=4.0,
         green=0.5):
    d = root / step / "runs" / f"controller={controller},seed={seed}"
    d.mkdir(parents=True)
    summ = {"controller": controller, "seed": seed, "plan_changes": 0 if controller == "open"
            else 7, "network": {"throughput_veh_h": {"section_outlet": outflow,
                                                     "network_exit": outflow + 600.0},
                                "time_loss_s": {"total": 36000.0},
                                "depart_delay_s": {"ramp": 7200.0}},
            "section": {"speed_mean_kmh": {"h": mean_h, "a": mean_a},
                        "speed_spread_kmh": {"h": sd_h, "a": sd_a}}}
    (d / "summary.json").write_text(json.dumps(summ))
    pd.DataFrame({"green_running": [green, green + 0.2]}).to_parquet(d / "periods.parquet")


@pytest.fixture
def ablation_dir(tmp_path):
    root = tmp_path / "ablation"
    for seed in (1, 2, 3):
        _run(root, "identified", "open", seed, 4400.0, 40.0, 17.0)
        _run(root, "estimator", "etc", seed, 4300.0 + seed, 40.0 + seed, 17.0 + seed ** 2,
             14.0 + seed, 4.0 + 2 * seed)
        _run(root, "meter", "open", seed, 4500.0, 41.0, 16.0)
        _run(root, "meter", "etc", seed, 4600.0, 42.0 - seed, 15.0 + seed, 14.0 + seed,
             5.0 + 2 * seed)
    return root


def test_runs_pair_with_their_steps_open_loop_or_identifieds(ablation_dir):
    df = mech.collect(ablation_dir)
    assert df["step"].drop_duplicates().tolist() == ["identified", "estimator", "meter"]
    assert df["green_mean"].iloc[0] == pytest.approx(0.6)
    d = mech.paired(df)
    est = d[d["step"] == "estimator"]
    assert est["d_section_outflow_veh_h"].tolist() == [-99.0, -98.0, -97.0]   # - identified
    met = d[d["step"] == "meter"]
    assert met["d_section_outflow_veh_h"].tolist() == [100.0, 100.0, 100.0]   # - its own
    assert met["d_time_loss_veh_h"].tolist() == [0.0, 0.0, 0.0]


def test_the_spread_change_at_equal_mean_speed_removes_the_common_slope(ablation_dir):
    d = mech.paired(mech.collect(ablation_dir))
    equal = mech.at_equal_mean_speed(d).set_index(["class", "step"])
    # AV: every pair on d_sd = 2 d_mean (estimator) or 2 d_mean + 1 (meter): slope 2
    assert equal.loc[("a", "estimator"), "slope"] == pytest.approx(2.0)
    assert equal.loc[("a", "estimator"), "d_sd_at_equal_mean_kmh"] == pytest.approx(0.0)
    assert equal.loc[("a", "meter"), "d_sd_at_equal_mean_kmh"] == pytest.approx(1.0)
    assert equal.loc[("h", "estimator"), "n"] == 3
    text = mech.equal_markdown(mech.at_equal_mean_speed(d))
    assert text.splitlines()[2].startswith("| estimator | etc | ")


def test_the_study_writes_its_tables_and_figures(run_study, ablation_dir, tmp_path):
    levels = tmp_path / "levels.csv"
    pd.DataFrame({"green_share": [0.2, 0.8], "outflow_mean_veh_h": [4395.0, 3180.0]}) \
        .to_csv(levels, index=False)
    out = tmp_path / "out"
    assert run_study("ablation-mechanism", "--ablation", ablation_dir, "--levels", levels,
                     "--out", out, "--docs", tmp_path / "docs") == 0
    assert len(pd.read_csv(out / "mechanism.csv")) == 12
    assert (out / "map.png").stat().st_size > 10_000 and (out / "shift.png").is_file()
    page = (tmp_path / "docs" / "control_in_sumo.md").read_text()
    assert "![mechanism_map.png](control_in_sumo/mechanism_map.png)" in page
    assert (tmp_path / "docs" / "control_in_sumo" / "mechanism.csv").is_file()
    assert mech.read_levels(levels) == {0.2: 4395.0, 0.8: 3180.0}


def test_an_ablation_without_identifieds_open_loop_is_refused(ablation_dir):
    df = mech.collect(ablation_dir)
    with pytest.raises(StudyError, match="no open loop of step 'identified'"):
        mech.paired(df[df["step"] != "identified"])


def test_the_study_runs_from_python_with_its_options(ablation_dir, tmp_path):
    """Library code: MechanismOptions in, MechanismResult out; the command line builds
    the same options."""
    import argparse

    from arzsumo_studies.cli import ablation_mechanism as cli

    opts = mech.MechanismOptions(ablation=ablation_dir, out=tmp_path / "out", plots=False)
    result = mech.run_mechanism(opts)
    assert len(result.runs) == 12 and len(result.paired) == 6
    assert result.means.loc[("meter", "etc"), "d_section_outflow_veh_h"] == 100.0
    assert result.means.loc[("estimator", "etc"), "d_section_outflow_veh_h"] == -98.0
    assert [p.name for p in result.files] == ["mechanism.csv", "at_equal_mean_speed.csv",
                                              "at_equal_mean_speed.md"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--ablation", str(ablation_dir), "--out",
                                          str(tmp_path / "out"), "--no-plots"])) == opts
    with pytest.raises(StudyError, match="is not a directory"):
        mech.run_mechanism(mech.MechanismOptions(ablation=tmp_path / "none"))
