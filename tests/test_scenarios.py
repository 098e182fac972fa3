import pytest

from arzsumo.errors import ScenarioError
from arzsumo.scenario import load_scenario, scenario_from_dict


def test_scenario_units_are_converted_to_si():
    sc = scenario_from_dict({"model": {"preset": "paper_base", "v_free_h_kmh": 72,
                                       "vehicle_width_m": 2.07},
                             "equilibrium": {"rho_h_veh_km": 110, "rho_a_veh_km": 95}})
    assert sc.params.v_free_h == pytest.approx(20.0)
    assert sc.equilibrium.rho_h == pytest.approx(0.110)


def test_scenario_from_demand():
    sc = scenario_from_dict({"equilibrium": {"demand_h_veh_h": 4104, "demand_a_veh_h": 1560}})
    assert sc.equilibrium.q_h * 3600 == pytest.approx(4104)


@pytest.mark.parametrize(("data", "error", "match"), [
    ({"modle": {}}, ScenarioError,
     r"unknown key 'modle' \(did you mean 'model'\?\); allowed: actuation, alinea, description, "
     r"design, disturbance, "
     r"equilibrium"),
    ({"model": {"spacing_x_m": 3}}, ScenarioError, r"\[model\] unknown key 'spacing_x_m'"),
    ({"model": {"tau_h_s": "fast"}}, ScenarioError,
     r'\[model\] tau_h_s = "fast" is not allowed: a finite number'),
    ({"model": {"preset": "paper"}}, ScenarioError,
     r'\[model\] preset = "paper" is not allowed: one of paper_aggressive'),
    ({"equilibrium": {"rho_h_veh_km": -5}}, ScenarioError,
     r"\[equilibrium\] rho_h_veh_km = -5 is not allowed: a density > 0 veh/km"),
    ({"equilibrium": {"rho_h_veh_km": 200, "rho_a_veh_km": 120}}, ScenarioError,
     r"AO = .* below its maximum"),
    ({"equilibrium": {"demand_h_veh_h": 9000, "demand_a_veh_h": 4000}}, ScenarioError,
     r"exceeds what the fundamental diagram can carry"),
    ({"equilibrium": {"rho_h_veh_km": 110, "demand_h_veh_h": 100}}, ScenarioError,
     r"not several"),
    ({"equilibrium": {"penetration": 0.5}}, ScenarioError, r"total_flow_veh_h is missing"),
    ({"equilibrium": {"total_flow_veh_h": 5000, "penetration": 1.2}}, ScenarioError,
     r"penetration = 1.2 is not allowed"),
    ({"equilibrium": {"total_flow_veh_h": 20000, "penetration": 0.5}}, ScenarioError,
     r"flow = 20000 veh/h is not allowed at penetration 0.500: at most \d+ veh/h"),
    ({"equilibrium": {"v_h_kmh": 32}}, ScenarioError,
     r"\[equilibrium\] v_h_kmh = 32.00 km/h disagrees"),
])
def test_bad_scenarios_name_field_and_value(data, error, match):
    with pytest.raises(error, match=match):
        scenario_from_dict(data)


def test_missing_and_broken_files(tmp_path):
    with pytest.raises(ScenarioError, match="does not exist"):
        load_scenario(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[model\n")
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_scenario(bad)


def test_scenario_from_flow_and_penetration():
    sc = scenario_from_dict({"equilibrium": {"total_flow_veh_h": 5680.4733,
                                             "penetration": 0.5}})
    assert sc.equilibrium.q * 3600 == pytest.approx(5680.4733, rel=1e-9)
    assert sc.equilibrium.penetration == pytest.approx(0.5)


def test_shipped_scenarios_load(scenario_files):
    for path in scenario_files:
        load_scenario(path)
