"""``arzsumo study share-models``: its points, its options and the design it writes."""

from __future__ import annotations

import tomllib

import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.premise.map_points import mapped_demand
from arzsumo_studies.share_models import ShareOptions, _design, share_points, with_keys

from arzsumo.resources import shipped_scenarios_dir

NEWELL = tomllib.loads((shipped_scenarios_dir() / "control_newell.toml").read_text(
    encoding="utf-8"))


def test_each_share_is_a_mapped_point_whose_demand_splits_by_the_share():
    points = share_points((0.1, 0.18, 0.3, 0.5))
    assert [p.name for p in points] == ["av10", "av18", "av30", "av50"]
    assert all(p.mapped and not p.set for p in points)
    keys = mapped_demand(3860 / 3600, points[3].av_share)      # 50 %: an even split
    assert keys["demand_h_veh_h"] == keys["demand_a_veh_h"] == round(1.01 * 3860 / 2)
    data = with_keys(NEWELL, {f"sumo.{k}": v for k, v in keys.items()})
    assert data["sumo"]["fill_demand_a_veh_h"] == round(1.14 * 3860 / 2)
    assert NEWELL["sumo"]["demand_a_veh_h"] == 702               # the base is untouched


def test_keys_set_on_the_base_reach_every_shares_point_and_its_scenario_data():
    # a [sumo] key given to the study (SUMO's teleport on a merge that can deadlock) is
    # part of each share's point, so of its discharge runs and of the scenario written
    points = share_points((0.1, 0.5), {"sumo.time_to_teleport_s": 300})
    assert [dict(p.set) for p in points] == [{"sumo.time_to_teleport_s": 300}] * 2
    data = with_keys(NEWELL, points[1].set)
    assert data["sumo"]["time_to_teleport_s"] == 300
    assert "time_to_teleport_s" not in NEWELL["sumo"]


def test_the_command_line_reads_a_set_key_as_toml_and_refuses_other_tables():
    import argparse

    from arzsumo_studies.cli.share_models import sumo_assignment

    assert sumo_assignment("sumo.time_to_teleport_s=300") == ("sumo.time_to_teleport_s", 300)
    assert sumo_assignment('sumo.hv_model="IDM"') == ("sumo.hv_model", "IDM")
    for bad in ("run.warmup_s=600", "sumo.x", "sumo.hv_model=IDM", "sumo.a.b=1"):
        with pytest.raises(argparse.ArgumentTypeError, match="not"):
            sumo_assignment(bad)


@pytest.mark.parametrize(("changes", "field"), [
    ({"shares": (0.0, 0.5)}, "shares"), ({"shares": (0.3, 0.3)}, "shares"),
    ({"shares": ()}, "shares"), ({"validate_seeds": (3, 4)}, "validate_seeds"),
    ({"kernel_cells": 4}, "kernel_cells"), ({"jam_floor": "cell"}, "jam_floor"),
    ({"wave_weight": -1.0}, "wave_weight"),
    ({"sumo_keys": {"run.warmup_s": 600}}, "sumo_keys"),
    ({"sumo_keys": {"sumo.": 1}}, "sumo_keys"), ({"sumo_keys": {"sumo.a.b": 1}}, "sumo_keys"),
    ({"sumo_keys": {"sumo.demand_h_veh_h": 2000}}, "demand_h_veh_h"),
    ({"sumo_keys": (("sumo.seed", 1), ("sumo.seed", 2))}, "sumo_keys")])
def test_options_that_cannot_make_a_share_model_are_refused(changes, field):
    with pytest.raises(StudyError, match=field):
        ShareOptions(**changes)


def test_the_design_is_design_check_autos_and_keeps_the_bases_dead_band():
    # control_newell's [design] was chosen by design-check --auto (100 cells) for this
    # model: the study's design of the same scenario gives it back to its 6 digits
    table, cannot = _design(NEWELL, NEWELL, 100)
    want = NEWELL["design"]
    for key in ("mu", "sigma", "zeta", "eta", "B"):
        assert table[key] == pytest.approx(want[key], rel=1e-5), key
    assert table["A"] == pytest.approx(want["A"], rel=1e-5)
    assert table["noise_from_estimate"] is True
    assert len(cannot) == 1                      # esthm #1, as its comment says


def test_the_idm_streams_model_carries_its_waves_and_its_design_is_design_check_autos():
    # stop_and_go_idm's model was identified in two stages with the blocks' jam floor:
    # lambda_4 at its equilibrium within 4 % of SUMO's waves there (-29.8 HV, -30.7 AV
    # km/h on the held-out seeds); its [design] is design-check --auto's for that model
    from arzsumo.model.characteristic import characteristic_speeds
    from arzsumo.scenario import scenario_from_dict
    from arzsumo.units import ms_to_kmh

    idm = tomllib.loads((shipped_scenarios_dir() / "stop_and_go_idm.toml").read_text(
        encoding="utf-8"))
    sc = scenario_from_dict(idm, "stop_and_go_idm.toml")
    eq = sc.equilibrium
    lam4 = ms_to_kmh(float(min(characteristic_speeds(sc.params, eq.rho_h, eq.rho_a))))
    assert lam4 == pytest.approx(-29.33, abs=0.01)
    table, cannot = _design(idm, idm, 100)
    for key in ("mu", "sigma", "zeta", "eta", "B"):
        assert table[key] == pytest.approx(idm["design"][key], rel=1e-5), key
    assert table["A"] == pytest.approx(idm["design"]["A"], rel=1e-5)
    assert len(cannot) == 1                      # esthm #1, as its comment says


def test_the_command_on_the_page_gives_back_the_options():
    import shlex
    from pathlib import Path

    from arzsumo_studies.cli.share_models import options
    from arzsumo_studies.share_models import command

    from .conftest import parse

    opts = ShareOptions(shares=(0.1, 0.5), train_seeds=(1, 2), validate_seeds=(3, 4),
                        jam_floor="blocks", wave_weight=3.0,
                        kernel_cells=60,
                        sumo_keys={"sumo.time_to_teleport_s": 300, "sumo.hv_model": "IDM",
                                   "sumo.fcd": False, "sumo.note": "a b's"})
    line = command(opts, Path("scenarios/stop_and_go_idm.toml"))
    argv = shlex.split(line)[3:]                      # after "arzsumo study share-models"
    again = options(parse("share-models", *argv))
    for field in ("shares", "train_seeds", "validate_seeds", "jam_floor", "wave_weight",
                  "sumo_keys", "diagram", "kernel_cells"):
        assert getattr(again, field) == getattr(opts, field), field
    assert again.scenario == Path("scenarios/stop_and_go_idm.toml")
