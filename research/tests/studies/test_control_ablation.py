"""``arzsumo study control-ablation``: each step changes one piece of the regulation
scenario and nothing else; the table pairs each step with the full configuration."""

from __future__ import annotations

import dataclasses
import tomllib

import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.control import ablation as control_ablation
from arzsumo_studies.control.study import DISTURBANCE, experiment_scenario
from arzsumo_studies.recorded import RecordedRuns

from arzsumo.errors import ScenarioError
from arzsumo.model import characteristic_speeds, linearize
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import scenario_from_dict

#: the default stream with the power-law model: the ablation's committed records ran on it
BASE = tomllib.loads((shipped_scenarios_dir() / "default_power_law.toml").read_text(
    encoding="utf-8"))


def _flat(data: dict) -> dict:
    return {f"{t}.{k}": v for t, table in data.items() if isinstance(table, dict)
            for k, v in table.items()}


@pytest.mark.parametrize("step", list(control_ablation.STEPS))
def test_each_step_is_a_valid_scenario_that_changes_one_piece(step):
    data = control_ablation.step_scenario(BASE, step)
    sc = scenario_from_dict(data, f"{step}.toml")
    full = _flat(experiment_scenario(BASE, "regulation"))
    changed = {k for k, v in _flat(data).items() if full.get(k) != v}
    tables = {k.partition(".")[0] for k in changed}
    if step == "power-law":                          # the base is the power law
        assert not changed
        return
    assert len(tables) == 1, changed                 # one table of the configuration
    if step == "raw-cells":
        assert sc.estimation.method == "none"
    if step == "predictor":
        assert sc.actuation.delay_compensation == control_ablation.PREDICTION_S
    if step == "predictor-measured":
        assert sc.actuation.delay_compensation == control_ablation.MEASURED_DEAD_TIME_S
    if step == "fixed-cycle":
        assert sc.sumo.meter_mode == "fixed_cycle" and control_ablation.STEPS[step][2]
    if step == "wave-matched":
        full_sc = scenario_from_dict(experiment_scenario(BASE, "regulation"))
        eq, eq0 = sc.equilibrium, full_sc.equilibrium
        lam4 = characteristic_speeds(sc.params, eq.rho_h, eq.rho_a)[3] * 3.6
        lam4_0 = characteristic_speeds(full_sc.params, eq0.rho_h, eq0.rho_a)[3] * 3.6
        assert lam4 == pytest.approx(control_ablation.WAVE_SPEED_KMH, abs=1e-6)
        assert lam4_0 > -3.0                            # the identified model: -2.55
        assert (eq.v_h, eq.v_a) == pytest.approx((eq0.v_h, eq0.v_a), rel=1e-9)
        assert changed == {f"model.{k}" for k in ("gamma_h", "gamma_a", "ao_max_h",
                                                  "ao_max_a")}


def test_the_table_pairs_each_step_with_the_full_configuration():
    def runs(tts_h: dict[str, float]) -> pd.DataFrame:
        return pd.DataFrame([{"controller": c, "seed": s,
                              "network_whole_demand.time_spent_s.total":
                                  3600.0 * (v + s), "plan_changes": 10.0 * s}
                             for c, v in tts_h.items() for s in (1, 2, 3)])
    full = runs({"backstepping": 100.0, "etc": 101.0})
    step = runs({"backstepping": 102.0, "etc": 100.5})
    text = control_ablation.table({"raw-cells": step}, full, [1, 2, 3])
    bs = next(x for x in text.splitlines() if x.startswith("| raw-cells | backstepping"))
    etc = next(x for x in text.splitlines() if x.startswith("| raw-cells | etc"))
    assert "| +2 [+2, +2] {+2, +2} 0/3 |" in bs              # 2 veh h worse on every seed
    assert "| -0.5 [-0.5, -0.5] {-0.5, -0.5} 3/0 |" in etc
    assert "| +0 [+0, +0] {+0, +0} 0/0 |" in bs               # the same plan changes: ties
    assert not any(x.startswith("| full |") for x in text.splitlines())   # no open loop
    # with the (borrowed) open loop among the step's runs: each step and the full
    # configuration are also given against it
    with_open = pd.concat([step, runs({"open": 103.0})], ignore_index=True)
    text = control_ablation.table({"raw-cells": with_open}, full, [1, 2, 3])
    rows = {tuple(c.strip() for c in x.split("|")[1:4]): x for x in text.splitlines()}
    assert "| -1 [-1, -1] {-1, -1} 3/0 |" in rows[("raw-cells", "backstepping", "open")]
    assert "| -3 [-3, -3] {-3, -3} 3/0 |" in rows[("full", "backstepping", "open")]
    assert "| +2 [+2, +2] {+2, +2} 0/3 |" in rows[("raw-cells", "backstepping", "full")]
    # a step run on one law only (--laws etc) shows no rows of the other
    etc_only = runs({"etc": 100.5})
    text = control_ablation.table({"raw-cells": etc_only}, full, [1, 2, 3])
    assert any(x.startswith("| raw-cells | etc") for x in text.splitlines())
    assert not any(x.startswith("| raw-cells | backstepping") for x in text.splitlines())
    # without a full configuration: each step against the open loop only
    text = control_ablation.table({"raw-cells": with_open}, None, [1, 2, 3])
    rows = {tuple(c.strip() for c in x.split("|")[1:4]): x for x in text.splitlines()}
    assert "| -1 [-1, -1] {-1, -1} 3/0 |" in rows[("raw-cells", "backstepping", "open")]
    assert not any(k[0] == "full" or k[2] == "full" for k in rows)


def test_the_full_configuration_may_come_from_elsewhere_or_not_at_all(run_study, tmp_path):
    """--full names another store (checked like --control), --without-full needs none;
    the two together are refused by the command line."""
    with pytest.raises(StudyError, match=f"--full = '{tmp_path / 'f'}' is not allowed"):
        run_study("control-ablation", "--full", tmp_path / "f", "--out", tmp_path / "a")
    with pytest.raises(SystemExit):
        run_study("control-ablation", "--full", tmp_path, "--without-full",
                  "--out", tmp_path / "a")


def test_unknown_steps_and_a_missing_control_study_are_refused(run_study, tmp_path):
    with pytest.raises(StudyError, match="--steps = 'meter' is not allowed"):
        run_study("control-ablation", "--steps", "meter", "--out", tmp_path / "a")
    with pytest.raises(StudyError, match="has no finished regulation run "
                       "controller=backstepping,seed=1 of this scenario; allowed: the --out"):
        run_study("control-ablation", "--control", tmp_path, "--out", tmp_path / "a")
    assert not (tmp_path / "a").exists()


def test_a_step_of_the_disturbance_experiment_keeps_the_slowdown_and_its_own_name():
    data = control_ablation.step_scenario(BASE, "wave-matched", "disturbance")
    full = experiment_scenario(BASE, "disturbance")
    assert data["disturbance"] == full["disturbance"]
    changed = {k for k, v in _flat(data).items() if _flat(full).get(k) != v}
    assert {k.partition(".")[0] for k in changed} == {"model"}
    assert data["name"].endswith("-ablation-wave-matched-disturbance")
    assert control_ablation.step_name("wave-matched", "disturbance") != \
        control_ablation.step_name("wave-matched")      # separate stores
    # the regulation step keeps the name its records were made under
    assert control_ablation.step_scenario(BASE, "wave-matched")["name"].endswith(
        "-ablation-wave-matched")


def test_a_step_the_scenario_does_not_admit_is_refused_before_anything_runs(
        run_study, tmp_path, monkeypatch):
    from arzsumo_studies.control import ablation_steps

    monkeypatch.setattr(ablation_steps, "WAVE_SPEED_KMH", 100.0)   # faster than any car
    with pytest.raises(StudyError, match=r"--steps = 'wave-matched' is not allowed on "
                                         r"--scenario = .*out of this model family's reach"):
        run_study("control-ablation", "--steps", "wave-matched", "--control",
                  tmp_path / "none", "--scenario", shipped_scenarios_dir()
                  / "default_power_law.toml", "--out", tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_on_a_newell_model_wave_matched_is_not_a_default_step_and_is_refused_by_name(
        run_study, tmp_path):
    # the Newell family sets its wave speeds directly: no exponents to move
    newell = tomllib.loads((shipped_scenarios_dir() / "default.toml").read_text("utf-8"))
    assert newell["model"]["family"] == "newell"
    assert control_ablation.default_steps(newell) == tuple(
        s for s in control_ablation.DEFAULT_STEPS if s != "wave-matched")
    assert control_ablation.default_steps(BASE) == control_ablation.DEFAULT_STEPS
    with pytest.raises(StudyError, match=r"--steps = 'wave-matched' is not allowed on "
                                         r"--scenario = .*default.toml: family = 'newell'"):
        run_study("control-ablation", "--steps", "wave-matched", "--control",
                  tmp_path / "none", "--out", tmp_path / "out")
    assert not (tmp_path / "out").exists()


NEWELL = tomllib.loads((shipped_scenarios_dir() / "control_newell.toml").read_text(
    encoding="utf-8"))


@pytest.mark.parametrize("step", ["power-law", "paper-trigger", "unit-gain", "dead-band",
                                  "quarter-law", "paper-eta"])
def test_the_judged_configurations_steps_each_change_what_they_name(step):
    data = control_ablation.step_scenario(NEWELL, step)
    sc = scenario_from_dict(data, f"{step}.toml")
    full = scenario_from_dict(experiment_scenario(NEWELL, "regulation"), "full.toml")
    assert full.design.noise_from_estimate and full.actuation.meter_gain == 2.0
    if step == "power-law":
        lam4 = linearize(sc.equilibrium).eigenvalues[3] * 3.6
        assert lam4 == pytest.approx(-2.55, abs=0.01)          # the former default's
        assert linearize(full.equilibrium).eigenvalues[3] * 3.6 == pytest.approx(-32.6,
                                                                                  abs=0.1)
        assert sc.design.noise_from_estimate and sc.design.mu != full.design.mu
        assert sc.actuation == full.actuation
    if step == "paper-trigger":
        assert not sc.design.noise_from_estimate
        assert sc.design.with_(noise_from_estimate=True) == full.design
    if step == "unit-gain":
        assert sc.actuation.meter_gain == 1.0 and sc.design == full.design
    if step == "paper-eta":                          # m forgets at the paper's rate
        assert sc.design == full.design.with_(eta=0.9) and sc.actuation == full.actuation
    if step == "quarter-law":                        # the meter asked for a quarter
        assert sc.actuation.meter_gain == 8.0 and sc.design == full.design
        assert dataclasses.replace(sc.actuation, meter_gain=2.0) == full.actuation
    if step == "dead-band":                          # by hand, in place of the measured
        assert not sc.design.noise_from_estimate and sc.design.noise_sd


def test_the_dead_band_step_is_unchanged_on_the_default():
    # its records in the committed store hold only while the step's scenario is the same
    data = control_ablation.step_scenario(BASE, "dead-band")
    want = experiment_scenario(BASE, "regulation")["design"] | {
        "noise_sd_kmh": list(control_ablation.DEAD_BAND_KMH), "noise_k": 2.0}
    assert data["design"] == want


def test_the_ablation_is_called_from_python_with_its_options():
    from arzsumo_studies.recorded import RecordedRuns

    opts = control_ablation.AblationOptions(RecordedRuns((1, 2)),
                                            steps=("unit-gain", "paper-trigger"))
    assert control_ablation.design(opts) == [
        "unit-gain: the laws on the paper's unit actuator (meter_gain 1); backstepping, "
        "etc on seeds 1,2",
        "paper-trigger: the ETC's trigger as in the paper (no measured dead band); "
        "backstepping, etc on seeds 1,2"]
    with pytest.raises(StudyError, match="steps"):
        control_ablation.AblationOptions(RecordedRuns((1,)), steps=("nope",))
    with pytest.raises(StudyError, match="experiment"):
        control_ablation.AblationOptions(RecordedRuns((1,)), experiment="rush-hour")


def test_the_power_law_step_on_a_placed_stream_keeps_its_plant_and_designs_anew():
    idm = tomllib.loads((shipped_scenarios_dir() / "stop_and_go_idm.toml").read_text(
        encoding="utf-8"))
    data = control_ablation.step_scenario(idm, "power-law")
    full = experiment_scenario(idm, "regulation")
    for table in ("equilibrium", "sumo", "initial", "run", "actuation"):
        assert data[table] == full[table]           # the section placed as before
    sc = scenario_from_dict(data, "power-law.toml")
    assert sc.params.family == "power"
    assert linearize(sc.equilibrium).eigenvalues[3] * 3.6 == pytest.approx(-5.66, abs=0.01)
    assert sc.design.noise_from_estimate
    assert sc.design.mu == pytest.approx(0.00606868)   # design-check --auto's choice
    assert sc.design != scenario_from_dict(full, "full.toml").design


def test_the_page_flag_names_the_page_the_table_goes_to(tmp_path):
    import argparse

    from arzsumo_studies.cli import control_ablation as cli

    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    args = parser.parse_args(["--docs", str(tmp_path), "--page", "control_idm",
                              "--steps", "quarter-law,speed-limit+acted-trigger",
                              "--seeds", "1,3", "--laws", "observer-etc"])
    opts = cli.options(args)
    assert (opts.page, opts.docs, opts.steps) == (
        "control_idm", tmp_path, ("quarter-law", "speed-limit+acted-trigger"))
    assert opts.laws == ("observer-etc",)
    with pytest.raises(StudyError, match=r"--steps = 'speed-limit\+nothing' is not allowed"):
        cli.options(parser.parse_args(["--steps", "speed-limit+nothing"]))
    assert cli.options(parser.parse_args([])).page == control_ablation.PAGE


def test_the_paper_eta_meets_the_conditions_the_designed_eta_meets():
    """esthm asks eta >= mu (1 - sigma) - gamma: the paper's faster eta on the IDM stream's
    design leaves every condition as it was (esthm #1 fails for both, the rest hold)."""
    from arzsumo.control.design_check import check_design
    from arzsumo.control.verify import sinusoidal_deviation
    from arzsumo.kernel_cache import cached_kernels
    from arzsumo.scenario import load_scenario

    sc = load_scenario(shipped_scenarios_dir() / "stop_and_go_idm.toml")
    lin = linearize(sc.equilibrium)
    kernels = cached_kernels(lin.system, sc.run.kernel_cells)
    w0 = lin.to_riemann(sinusoidal_deviation(lin, kernels.x), kernels.x)
    alpha_x = (w0[:-1, -1] - w0[:-1, -2]) / kernels.h
    held = []
    for eta in (sc.design.eta, control_ablation.PAPER_ETA):
        report = check_design(lin.system, kernels, sc.design.with_(eta=eta), alpha_x)
        held.append([(c.label, c.holds) for c in report.conditions])
    assert sc.design.eta == pytest.approx(sc.design.mu * (1 - sc.design.sigma), rel=1e-4)
    assert held[0] == held[1]
    assert [c for c, ok in held[1] if not ok] == ["esthm"]


def test_a_model_step_runs_its_own_open_loop_where_the_model_places_the_section():
    idm = experiment_scenario(tomllib.loads((shipped_scenarios_dir() / "stop_and_go_idm.toml"
                                             ).read_text(encoding="utf-8")), "regulation")
    assert control_ablation.own_open_loop("power-law", idm)          # placed: its own
    assert control_ablation.own_open_loop("wave-matched", idm)
    assert not control_ablation.own_open_loop("quarter-law", idm)    # the laws only
    warm = experiment_scenario(BASE, "regulation")                   # warmed up: borrowed
    assert not control_ablation.own_open_loop("power-law", warm)
    assert control_ablation.own_open_loop("fixed-cycle", warm)       # the plant itself


def test_joined_steps_make_each_change_in_order():
    joined = control_ablation.step_scenario(BASE, "speed-limit+acted-trigger")
    one = control_ablation.step_scenario(BASE, "speed-limit")
    assert joined["actuation"] == one["actuation"]
    assert joined["actuation"]["actuator"] == "speed_limit"
    assert joined["design"]["trigger_energy"] == "acted"
    assert control_ablation.is_step("speed-limit+acted-trigger")
    assert not control_ablation.is_step("speed-limit+speed-limit")
    assert not control_ablation.is_step("speed-limit+vsl")
    assert control_ablation.describe("speed-limit+acted-trigger").count(" and ") >= 1


def test_a_joined_step_of_unknown_parts_is_refused():
    with pytest.raises(StudyError, match=r"steps = \('predictor\+nothing',\) is not allowed"):
        control_ablation.AblationOptions(RecordedRuns(seeds=(1,)),
                                         steps=("predictor+nothing",))


def test_the_outlet_limit_meets_its_slowdown_on_the_merge_edge():
    """The disturbance experiment slows the edge past the merge, the outlet limit's own:
    refused there in one line; the merge-slowdown experiment slows the merge's edge, the
    same slowdown otherwise, and runs with the limit."""
    idm = tomllib.loads((shipped_scenarios_dir() / "stop_and_go_idm.toml").read_text(
        encoding="utf-8"))
    with pytest.raises(ScenarioError, match="actuator"):
        scenario_from_dict(control_ablation.step_scenario(idm, "speed-limit", "disturbance"),
                           "s.toml")
    data = control_ablation.step_scenario(idm, "speed-limit", "merge-slowdown")
    assert data["disturbance"] == {**DISTURBANCE, "edge": "merge"}
    assert data["name"] == "stop_and_go_idm-ablation-speed-limit-merge-slowdown"
    sc = scenario_from_dict(data, "s.toml")
    assert sc.actuation.actuator == "speed_limit" and sc.disturbance.edge == "merge"
    assert control_ablation.AblationOptions(RecordedRuns((1,)),
                                            experiment="merge-slowdown").experiment
