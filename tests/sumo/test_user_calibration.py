"""``arzsumo calibrate`` on a network the package does not ship: the runs are on the
user's network, the user's route files are scaled for the demand levels, and the written
scenario points back at the network and the meter curve beside it."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

from arzsumo.cli import main
from arzsumo.sumo.calibrate import SCALES
from tests.sumo import user_nets


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    d = tmp_path_factory.mktemp("two_lane_cal")
    user_nets.two_lane(d)
    (d / "a.toml").write_text(user_nets.TWO_LANE_TOML, encoding="utf-8")
    out = d / "cal"
    assert main(["calibrate", "--scenario", str(d / "a.toml"), "--quick", "--jobs", "1",
                 "--out", str(out)]) == 0
    return d, out


@pytest.mark.sumo
def test_the_levels_scale_the_users_route_files_on_the_users_road(calibrated):
    """The route file asks 3000 HV + 900 AV veh/h on the mainline (periods 1.2 s and 4 s):
    the medium level is that demand, the light one 0.4 of it; the shipped network's
    paper demands (5664 veh/h) would show instead if the run left the user's road."""
    _, out = calibrated
    runs = json.loads((out / "calibration.json").read_text(encoding="utf-8"))["runs"]
    inflow = {(r["level"], r["green_share"]): r["inflow"] * 3600 for r in runs}
    assert inflow[("medium", 0.0)] == pytest.approx(3900, rel=0.03)
    assert inflow[("light", 1.0)] / inflow[("medium", 1.0)] == pytest.approx(
        SCALES["light"], abs=0.03)


@pytest.mark.sumo
def test_the_calibrated_scenario_points_at_the_network_and_its_meter_curve(calibrated):
    d, out = calibrated
    data = tomllib.loads((out / "calibrated_model.toml").read_text(encoding="utf-8"))
    net = data["network"]
    assert Path(net["net_file"]) == (d / "two_lane.net.xml").resolve()
    assert [Path(p) for p in net["route_files"]] == [(d / "demand.rou.xml").resolve()]
    assert net["section_edges"] == ["s1", "s2", "s3"] and net["meter_tls"] == "rm1"
    assert data["sumo"]["meter_curve"] == "meter_curve.toml"
    assert (out / "meter_curve.toml").is_file()
    # the route files carry the demand: no demand key that the run would ignore
    assert not {"demand_h_veh_h", "demand_a_veh_h", "ramp_demand_veh_h"} & set(data["sumo"])
    # the section's length and width come from the network: 1500 m, two lanes of 3.5 m
    assert data["model"]["length_m"] == pytest.approx(1500.0)
    assert data["model"]["road_width_m"] == pytest.approx(7.0)
