"""The ablation's design: the steps, what each switches on, whose open loop it borrows,
and the table assembled from the steps' evaluations."""

from __future__ import annotations

import pandas as pd
import pytest
from arzsumo_studies.ablation import study as ablation
from arzsumo_studies.common import StudyError

from arzsumo.outdir import write_marker
from arzsumo.sweep.evaluate import OPEN_LOOP_INERT


def test_the_steps_are_the_documented_ones_in_order():
    assert ablation.STEP_NAMES == ("scenario", "identified", "estimator", "reference",
                                   "saturation", "design", "delay", "meter")
    assert ablation.run_order(["delay", "identified", "scenario"]) == \
        ["identified", "delay", "scenario"]


def test_the_base_has_no_controller_side_and_the_plain_fixed_cycle():
    side = ablation.controller_side()
    assert side == ("estimation", "sensing", "actuation", "design")
    assert set(side) < set(OPEN_LOOP_INERT)                 # the evaluation's own list
    data, borrow = ablation.step_scenario("identified")
    assert borrow is None
    assert not set(side) & set(data)
    assert "meter_mode" not in data["sumo"] and "meter_clearance_s" not in data["sumo"]
    assert data["alinea"]["target_pct"] == 50.1             # ALINEA's table is kept


def test_each_step_carries_the_changes_of_the_steps_before_it():
    est, _ = ablation.step_scenario("estimator")
    assert est["sensing"] == {"kinds": ["loops", "av_probes"], "loop_spacing_m": 250}
    assert est["estimation"] == {"method": "smoothing"}
    sat, _ = ablation.step_scenario("saturation")
    assert sat["estimation"] == {"method": "smoothing", "reference": "warmup",
                                 "reference_window_s": 300}
    assert sat["actuation"] == {"u_max_fraction": 0.2, "u_rate_max_veh_h_s": 100,
                                "ramp_bound": True, "anti_windup": True}
    delay, _ = ablation.step_scenario("delay")
    assert delay["actuation"]["delay_compensation_s"] == ablation.PREDICTION_S == 14.0
    assert delay["design"]["zeta"] == 0.00797514 and delay["design"]["B"] == 2.0


def test_the_meter_step_branches_from_design_and_runs_its_own_open_loop():
    meter, borrow = ablation.step_scenario("meter")
    assert borrow is None
    assert (meter["sumo"]["meter_mode"], meter["sumo"]["meter_clearance_s"]) == \
        ("one_per_green", 2)
    assert "delay_compensation_s" not in meter["actuation"]   # not on the delay step
    assert ablation.controllers_of("meter", borrow) == ["open", "backstepping", "etc"]


@pytest.mark.parametrize("name", ["scenario", "estimator", "reference", "saturation",
                                  "design", "delay"])
def test_steps_that_cannot_move_the_open_loop_borrow_that_of_identified(name):
    _, borrow = ablation.step_scenario(name)
    assert borrow == "identified"
    assert "open" not in ablation.controllers_of(name, borrow)


def test_the_scenario_step_takes_the_legacy_model_on_the_same_sumo_side():
    data, _ = ablation.step_scenario("scenario")
    legacy = ablation.scenario_data(ablation.shipped_scenario("legacy_default.toml"))
    ident, _ = ablation.step_scenario("identified")
    assert data["model"] == legacy["model"] and data["equilibrium"] == legacy["equilibrium"]
    assert data["sumo"] == ident["sumo"]


def test_an_unknown_step_is_refused():
    with pytest.raises(StudyError, match="'best' is not allowed: one of scenario"):
        ablation.step("best")


def test_list_prints_the_design_without_running(run_study, capsys, tmp_path):
    assert run_study("ablation", "--steps", "design,identified", "--seeds", "1-4",
                     "--list", "--out", tmp_path / "a") == 0
    assert capsys.readouterr().out.splitlines() == [
        "identified: open, alinea, backstepping, etc on seeds 1-4",
        "design: etc on seeds 1-4; open loop from identified"]
    assert not (tmp_path / "a").exists()


def _evaluation(path, controller_rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(controller_rows).to_csv(path, index=False)


def test_the_report_reads_the_steps_and_an_older_measure_name(run_study, tmp_path, capsys):
    out = tmp_path / "abl"
    out.mkdir()
    write_marker(out, "study-ablation")
    base = {"n": 10, "wins": 0, "losses": 0, "diff_ci_low": 0.0, "diff_ci_high": 0.0}
    _evaluation(out / "identified" / "evaluation.csv", [
        {**base, "measure": "plan_changes", "controller": "open", "mean": 0.0,
         "diff_mean": 0.0},
        {**base, "measure": "plan_changes", "controller": "etc", "mean": 12.0,
         "diff_mean": 12.0, "diff_ci_low": 10.0, "diff_ci_high": 14.0},
        {**base, "measure": "section.speed_sd_kmh.h", "controller": "etc", "mean": 17.5,
         "diff_mean": -0.25, "diff_ci_low": -0.5, "diff_ci_high": 0.0},
        {**base, "measure": "not.a.measure", "controller": "etc", "mean": 1.0,
         "diff_mean": 1.0}])
    assert run_study("ablation", "--report", "--out", out) == 0
    table = pd.read_csv(out / "ablation.csv")
    assert table["measure"].tolist() == ["plan_changes", "plan_changes",
                                         "section.speed_spread_kmh.h"]
    lines = (out / "ablation.md").read_text().splitlines()
    assert lines[2].startswith("| identified | open | ")
    assert "| 12 (+12 [+10, +14]) |" in lines[3] and "| 17.5 (-0.25 [-0.5, +0]) |" in lines[3]
    assert lines[0].count("|") == 2 + len(ablation.MEASURES) + 1
    assert "| identified | etc |" in capsys.readouterr().out


def test_every_steps_laws_are_sumo_controllers():
    from arzsumo.control.registry import controller_names

    laws = {law for s in ablation.STEPS for law in s.laws}
    assert laws == {"alinea", "backstepping", "etc"} and laws < set(controller_names("sumo"))


def _finished_runs(path, seeds):
    pd.DataFrame({"seed": seeds, "status": ["ok"] * len(seeds),
                  "controller": ["etc"] * len(seeds)}).to_parquet(path)


def test_the_report_names_the_seeds_its_steps_ran_on_not_the_default(run_study, tmp_path):
    out = tmp_path / "abl"
    out.mkdir()
    write_marker(out, "study-ablation")
    row = {"n": 2, "wins": 0, "losses": 0, "diff_ci_low": 0.0, "diff_ci_high": 0.0,
           "measure": "plan_changes", "controller": "etc", "mean": 12.0, "diff_mean": 12.0}
    for name in ("identified", "design"):
        _evaluation(out / name / "evaluation.csv", [row])
        _finished_runs(out / name / "summaries.parquet", [3, 4])
        (out / name / "evaluation.md").write_text("# evaluation\n")
        (out / "steps").mkdir(exist_ok=True)
        (out / "steps" / f"{name}.toml").write_text(f'name = "ablation-{name}"\n')
    assert run_study("ablation", "--report", "--out", out, "--docs", tmp_path / "docs") == 0
    page = (tmp_path / "docs" / "control_in_sumo.md").read_text()
    assert "is evaluated on seeds 3,4 (`arzsumo study ablation`)" in page
    _finished_runs(out / "design" / "summaries.parquet", [3, 4, 5])
    assert run_study("ablation", "--report", "--out", out, "--docs", tmp_path / "docs") == 0
    page = (tmp_path / "docs" / "control_in_sumo.md").read_text()
    assert "is evaluated on seeds identified: 3,4; design: 3-5 (`arzsumo" in page


def test_the_ablation_reports_from_python_with_its_options(tmp_path):
    """Library code: AblationOptions in (report only), AblationResult out; its design
    runs identified first, the command line builds the same options, and an unknown step
    is refused on construction."""
    import argparse

    from arzsumo_studies.cli import ablation as cli

    opts = ablation.AblationOptions(steps=("design", "identified"), seeds=(1, 2, 3, 4))
    assert ablation.design(opts) == [
        "identified: open, alinea, backstepping, etc on seeds 1-4",
        "design: etc on seeds 1-4; open loop from identified"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--steps", "design,identified", "--seeds",
                                          "1-4"])) == opts
    out = tmp_path / "abl"
    out.mkdir()
    write_marker(out, "study-ablation")
    base = {"n": 10, "wins": 0, "losses": 0, "diff_ci_low": 10.0, "diff_ci_high": 14.0}
    _evaluation(out / "identified" / "evaluation.csv", [
        {**base, "measure": "plan_changes", "controller": "etc", "mean": 12.0,
         "diff_mean": 12.0}])
    result = ablation.run_ablation(ablation.AblationOptions(report=True, out=out))
    assert result.code == 0
    assert result.table[["step", "controller", "mean"]].values.tolist() == [
        ["identified", "etc", 12.0]]
    assert [p.name for p in result.files] == ["ablation.csv", "ablation.md"]
    with pytest.raises(StudyError, match="--steps: 'best' is not allowed"):
        ablation.AblationOptions(steps=("identified", "best"))
