"""``arzsumo identify`` end to end with real SUMO (short runs), and its refusals."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from arzsumo.cli import main
from arzsumo.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "scenarios" / "legacy_default.toml"
#: 2 training + 1 validation seed, 60 s of open loop after 60 s of warm-up (the road is
#: full by then), the two relaxation times, 3 least-squares steps
ARGS = ["identify", str(DEFAULT), "--train-seeds", "1,2", "--validate-seeds", "3",
        "--which", "tau_h,tau_a", "--max-nfev", "3", "--horizon", "60", "--warmup", "60",
        "--workers", "2"]


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """A fresh run cache (and kernel cache) for this module."""
    path = tmp_path_factory.mktemp("cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(path))
        yield path


@pytest.fixture(scope="module")
def result(tmp_path_factory, cache):
    out = tmp_path_factory.mktemp("identify") / "out"
    assert main([*ARGS, "--out", str(out)]) == 0
    return out, json.loads((out / "identification.json").read_text())


@pytest.mark.sumo
def test_a_second_identification_reuses_the_cached_runs_and_gives_the_same_fit(
        result, cache, tmp_path):
    _, first = result
    assert len(list((cache / "identify-runs").glob("*.npz"))) == 3
    again = tmp_path / "again"
    assert main([*ARGS, "--out", str(again)]) == 0
    second = json.loads((again / "identification.json").read_text())
    # no SUMO this time (what is left is starting the worker processes)
    assert second["wall_time"]["sumo_s"] < 0.5 * first["wall_time"]["sumo_s"]
    assert second["parameters"] == first["parameters"]


@pytest.mark.sumo
def test_writes_the_files_and_a_scenario_that_loads_with_the_identified_values(result):
    out, doc = result
    for name in ("identified.toml", "identification.json", "fields.png", "scatter.png",
                 "spectrum.png"):
        assert (out / name).stat().st_size > 0, name
    sc, base = load_scenario(out / "identified.toml"), load_scenario(DEFAULT)
    for name in ("tau_h", "tau_a"):
        p = doc["parameters"][name]
        assert getattr(sc.params, name) == pytest.approx(p["value"], rel=1e-6)
        assert p["lower"] <= p["value"] <= p["upper"] and p["sigma"] >= 0.0
        assert p["start"] == getattr(base.params, name)
        assert doc["correlation"][name][name] == pytest.approx(1.0)
    for name in ("v_free_h", "ao_max_a", "gamma_h", "spacing_a", "vehicle_width"):
        assert getattr(sc.params, name) == pytest.approx(getattr(base.params, name),
                                                         rel=1e-12)
    eq = doc["equilibrium"]
    assert sc.equilibrium.rho_h == pytest.approx(eq["rho_h"], abs=1e-7)
    assert sc.equilibrium.rho_a == pytest.approx(eq["rho_a"], abs=1e-7)
    runs = doc["runs"]
    means = [runs[r]["mean_rho_h"] for r in ("seed1", "seed2")]
    assert eq["rho_h"] == pytest.approx(sum(means) / 2, rel=1e-12)
    # the same SUMO runs: only the vehicle speeds are now stated (as the runs had them)
    assert sc.sumo.with_(hv_max_speed=0.0, av_max_speed=0.0) == base.sumo
    assert sc.name == "legacy_default_identified"


@pytest.mark.sumo
def test_the_fit_does_not_increase_the_training_error_and_reports_both_sets(result):
    _, doc = result
    rmse, v_star = doc["rmse"], load_scenario(DEFAULT).equilibrium.v_h
    assert rmse["training"]["total"] <= rmse["start_training"]["total"] * (1 + 1e-12)
    assert set(rmse["training"]["runs"]) == {"seed1", "seed2"}
    assert set(rmse["validation"]["runs"]) == {"seed3"}
    for role in ("training", "validation"):
        for run in rmse[role]["runs"].values():
            v = run["v_h"]
            assert v["samples"] > 0 and 0.0 <= v["relative"] <= v["penalised"] + 1e-12
            assert v["absolute"] == pytest.approx(v["relative"] * v_star, rel=1e-12)
        for name, fails in doc["replay_failures"][role].items():
            assert fails["periods_not_predicted"] in range(61), name
            assert (fails["stopped_s"] is None) == (fails["periods_not_predicted"] == 0)
        for beyond in doc["beyond_ao_max"][role].values():
            assert beyond["observed"] == 60 * 20
            assert beyond["model"] >= max(beyond["h"], beyond["a"]) >= 0
    fit = doc["fit"]
    assert 1 <= fit["nfev"] <= 3 and fit["evaluations"] >= fit["nfev"]
    assert doc["settings"]["which"] == ["tau_h", "tau_a"]
    assert all(math.isfinite(doc["wall_time"][k]) for k in ("sumo_s", "fit_s", "total_s"))
    assert "?" not in doc["units_by_key"].values()
    assert doc["units_by_key"]["parameters.tau_h.sigma"] == "s"
    assert doc["units_by_key"]["rmse.validation.pooled.rho_a.absolute"] == "veh/m"


@pytest.mark.sumo
def test_the_identified_scenario_keeps_the_sumo_vehicles_of_the_runs(result):
    out, _ = result
    sc, base = load_scenario(out / "identified.toml"), load_scenario(DEFAULT)
    from arzsumo.sumo.vtypes import vehicle_types

    assert [v.max_speed for v in vehicle_types(sc.params, sc.sumo)] == pytest.approx(
        [v.max_speed for v in vehicle_types(base.params, base.sumo)], rel=1e-6)


def test_the_identified_scenario_is_valid_for_run(result, capsys):
    out, _ = result
    assert main(["run", str(out / "identified.toml"), "--dry-run"]) == 0
    assert "legacy_default_identified" in capsys.readouterr().out


def _refused(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exc:
        code = main(args)
        raise SystemExit(code)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err


@pytest.mark.parametrize(("change", "message"), [
    ({"--which": "tau_h,tau_x"}, "--which = tau_h,tau_x is not allowed: distinct names"),
    ({"--validate-seeds": "2,3"}, "seeds [2] are also training seeds"),
    ({"--train-seeds": "1,x"}, "--train-seeds = 1,x is not allowed"),
    ({"--vary": "sumo.nope=1,2"}, "--vary sumo.nope=1: "),
    ({"--vary": "green_share=0.4"}, "--vary = green_share=0.4 is not allowed: table.key"),
    ({"--vary": "sumo.green_share=0.4,7"}, "--vary sumo.green_share=7: "),
    ({"--bootstrap": "-1"}, "--bootstrap = -1 is not allowed"),
    ({"--jam-floor": "jam"}, "--jam-floor: invalid choice: 'jam'"),
    ({"--jam-floor": "blocks"}, "--jam-floor = blocks is not allowed without --diagram"),
])
def test_bad_input_exits_2_with_one_line_before_any_run(change, message, tmp_path, capsys):
    args = list(ARGS)
    for flag, value in change.items():
        if flag in args:
            args[args.index(flag) + 1] = value
        else:
            args += [flag, value]
    err = _refused([*args, "--out", str(tmp_path / "out")], capsys)
    assert message in err
    assert not (tmp_path / "out").exists()


@pytest.mark.sumo
def test_an_existing_result_is_kept_without_overwrite(result, capsys):
    out, _ = result
    err = _refused([*ARGS, "--out", str(out)], capsys)
    assert "identify" in err and "--overwrite" in err


def test_vary_plans_every_seed_at_every_point_of_the_product():
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.workflows.identify.study import make_setup, plan

    setup = make_setup(load_scenario(DEFAULT), [1, 2], [7], horizon=60.0, warmup=30.0,
                       vary=["sumo.green_share=0.4,0.6", "sumo.ramp_demand_veh_h=900,1200"],
                       which="tau_a,gamma_h", workers=1)
    assert [p.label for p in setup.points] == [
        "sumo.green_share=0.4, sumo.ramp_demand_veh_h=900",
        "sumo.green_share=0.4, sumo.ramp_demand_veh_h=1200",
        "sumo.green_share=0.6, sumo.ramp_demand_veh_h=900",
        "sumo.green_share=0.6, sumo.ramp_demand_veh_h=1200"]
    tasks = plan(setup)
    assert len(tasks) == 12
    assert [t.role for t in tasks] == ["training"] * 8 + ["validation"] * 4
    assert tasks[3].run_id == "p1-seed2" and tasks[-1].run_id == "p3-seed7"
    run = scenario_from_dict(tasks[5].tables, tasks[5].source)
    assert run.sumo.green_share == 0.6 and run.sumo.ramp_demand == pytest.approx(900 / 3600)
    assert run.run.controller == "open" and run.run.warmup == 30.0 and run.sumo.horizon == 60.0
    assert setup.which == ("tau_a", "gamma_h") and setup.options.cells == run.run.twin_cells


def test_the_replay_inlet_is_the_cell_transmission_rule_and_the_bridge_keeps_its_own():
    from arzsumo.bridge.replay_data import replay_options_of
    from arzsumo.errors import ScenarioError
    from arzsumo.workflows.identify.study import make_setup

    sc = load_scenario(DEFAULT)
    assert make_setup(sc, [1], [2], workers=1).options.inlet == "ctm"
    assert make_setup(sc, [1], [2], workers=1, inlet="ghost").options.inlet == "ghost"
    assert replay_options_of(sc.run).inlet == "ghost"          # the bridge's replay twin
    with pytest.raises(ScenarioError, match="--inlet = wall is not allowed: one of ctm, supply"):
        make_setup(sc, [1], [2], workers=1, inlet="wall")


def test_the_fit_starts_from_an_ao_max_that_holds_the_observed_occupancy():
    import numpy as np

    from arzsumo.identify import ReplayData
    from arzsumo.model.fd import area_occupancy
    from arzsumo.workflows.identify.scores import start_params

    params = load_scenario(DEFAULT).params                   # AO_max_a 0.56
    rho = np.array([0.120, 8.0, 0.065, 4.0])                 # AO above 0.56
    ao = float(area_occupancy(params, rho[0], rho[2]))
    fields = np.tile(rho[None, :, None], (2, 1, 3))
    data = ReplayData.from_arrays([1.0, 2.0], [10.0, 20.0, 30.0], fields, fields[0],
                                  np.tile(rho, (2, 1)), [1.0, 1.0])
    start = start_params(params, [data], 0.9)
    assert ao > params.ao_max_a
    assert start.ao_max_a == pytest.approx(ao / 0.9) and start.ao_max_h >= params.ao_max_h
    assert start_params(start, [data], 0.9) == start             # already holds it


#: the same runs, two stages: the Newell diagram from the windows, then the relaxation times
TWO_STAGE = [a for a in ARGS if a not in ("--which", "tau_h,tau_a")] + [
    "--diagram", "newell", "--wave-speed-kmh", "-30"]


@pytest.mark.sumo
def test_two_stages_write_a_newell_model_from_the_same_runs(result, cache, tmp_path):
    out = tmp_path / "two"
    assert main([*TWO_STAGE, "--out", str(out)]) == 0
    doc = json.loads((out / "identification.json").read_text())
    assert len(list((cache / "identify-runs").glob("*.npz"))) == 3      # no new SUMO run
    assert (out / "diagram.png").stat().st_size > 0
    one = doc["stage_one"]
    assert one["fit"]["family"] == "newell" and one["fit"]["blocks"] >= 10
    assert one["fit"]["wave_speed"] == pytest.approx(-30 / 3.6)
    assert doc["settings"]["which"] == ["tau_h", "tau_a"]
    sc = load_scenario(out / "identified.toml")
    assert sc.params.family == "newell"
    for name in ("wave_speed_h", "wave_speed_a", "ao_max_h", "ao_max_a"):
        assert getattr(sc.params, name) == pytest.approx(one["fit"][name], rel=1e-6)
    assert sc.params.tau_h == pytest.approx(doc["parameters"]["tau_h"]["value"], rel=1e-6)
    # the held-out run under the scenario's own model, beside the identified one
    assert set(doc["scenario_model_validation"]["runs"]) == {"seed3"}
    assert set(one["wave_gap"]) == {"training", "validation"}


@pytest.mark.sumo
def test_the_jam_floor_reaches_stage_one(result, cache, tmp_path, monkeypatch):
    """cells: stage 1 is bounded by every replayed cell (the largest cell AO over the
    replay's AO limit); blocks: by the blocks alone (no floor handed on)."""
    import arzsumo.workflows.identify.study as st

    handed: dict[str, object] = {}

    class StopError(Exception):
        pass

    def fake(*args, floor=None, **kwargs):
        handed["floor"] = floor
        raise StopError

    monkeypatch.setattr(st, "fit_stage_one", fake)
    for floor, want in (("cells", float), ("blocks", type(None))):
        with pytest.raises(StopError):
            main([*TWO_STAGE, "--jam-floor", floor, "--out", str(tmp_path / floor)])
        assert isinstance(handed["floor"], want), floor
    assert len(list((cache / "identify-runs").glob("*.npz"))) == 3      # no new SUMO run


@pytest.mark.sumo
def test_which_and_diagram_together_are_refused_in_one_line(cache, tmp_path, capsys):
    code = main([*ARGS, "--diagram", "newell", "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err
    assert "--which = tau_h,tau_a is not allowed with --diagram" in err
    assert not (tmp_path / "x").exists()


def test_the_cli_offers_the_jam_floors_the_study_knows():
    import argparse

    from arzsumo.cli.identify import register
    from arzsumo.workflows.identify.study import JAM_FLOORS

    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    sub = parser._subparsers._group_actions[0].choices["identify"]
    flag = next(a for a in sub._actions if "--jam-floor" in a.option_strings)
    assert tuple(flag.choices) == JAM_FLOORS and flag.default == JAM_FLOORS[0]
