import numpy as np
import pytest

from arzsumo.errors import DemandError, ModelError
from arzsumo.model import (
    ModelParameters,
    equilibrium_at_penetration,
    equilibrium_from_demand,
    equilibrium_from_densities,
    linearize,
)
from arzsumo.units import kmh_to_ms, veh_h_to_veh_s

P = ModelParameters()
DEMANDS = [(4555, 1955), (4104, 1560), (3461, 1505)]   # Table diffdemands, veh/h


@pytest.mark.parametrize(("q_h", "q_a"), DEMANDS)
@pytest.mark.parametrize("branch", ["congested", "free"])
def test_demand_to_density_round_trips(q_h, q_a, branch):
    eq = equilibrium_from_demand(P, veh_h_to_veh_s(q_h), veh_h_to_veh_s(q_a), branch)
    assert eq.q_h == pytest.approx(veh_h_to_veh_s(q_h), rel=1e-10)
    assert eq.q_a == pytest.approx(veh_h_to_veh_s(q_a), rel=1e-10)
    back = equilibrium_from_densities(P, eq.rho_h, eq.rho_a)
    assert back.v_h == pytest.approx(eq.v_h)


def test_branches_differ_and_congested_is_denser():
    q = veh_h_to_veh_s(4104), veh_h_to_veh_s(1560)
    cong = equilibrium_from_demand(P, *q, "congested")
    free = equilibrium_from_demand(P, *q, "free")
    assert cong.ao > free.ao + 0.1
    assert linearize(cong).regime == "congested"
    assert linearize(free).regime == "free"


def test_densities_round_trip_through_demand():
    eq = equilibrium_from_densities(P, 0.11, 0.095)
    again = equilibrium_from_demand(P, eq.q_h, eq.q_a, "congested")
    assert (again.rho_h, again.rho_a) == pytest.approx((0.11, 0.095), rel=1e-9)


def test_demand_above_capacity_is_refused_with_the_capacity():
    with pytest.raises(DemandError, match=r"demand = 12000 veh/h .* at most \d+ veh/h"):
        equilibrium_from_demand(P, veh_h_to_veh_s(8000), veh_h_to_veh_s(4000))


def test_penetration_and_flows():
    eq = equilibrium_from_densities(P, 0.11, 0.095)
    assert eq.penetration == pytest.approx(95 / 205)
    assert eq.q == pytest.approx(eq.rho_h * eq.v_h + eq.rho_a * eq.v_a)


def test_stated_speeds_must_match_the_fundamental_diagram():
    eq = equilibrium_from_densities(P, 0.11, 0.095)
    equilibrium_from_densities(P, 0.11, 0.095, v_h=eq.v_h * 1.015)   # within 2 %
    with pytest.raises(ModelError, match=r"v_h = 32.00 km/h .* Ve = 35.90 km/h"):
        equilibrium_from_densities(P, 0.11, 0.095, v_h=kmh_to_ms(32))


@pytest.mark.parametrize(("rho_h", "rho_a", "match"), [
    (-0.01, 0.095, r"rho_h = -0.01"),
    (0.11, 0.0, r"rho_a = 0.0"),
    (0.2, 0.12, r"AO = 1.04\d* .*below its maximum 0.85"),
    (np.nan, 0.1, r"rho_h = nan"),
])
def test_bad_densities_are_named(rho_h, rho_a, match):
    with pytest.raises(ModelError, match=match):
        equilibrium_from_densities(P, rho_h, rho_a)


@pytest.mark.parametrize("penetration", [0.44, 0.47, 0.50, 0.53])
@pytest.mark.parametrize("branch", ["congested", "free"])
def test_penetration_helper_keeps_the_inflow_and_hits_the_share(penetration, branch):
    base = equilibrium_from_densities(P, 0.110, 0.095)
    eq = equilibrium_at_penetration(P, base.q, penetration, branch)
    assert eq.q == pytest.approx(base.q, rel=1e-10)
    assert eq.penetration == pytest.approx(penetration, rel=1e-12)
    assert linearize(eq).regime == ("congested" if branch == "congested" else "free")
    again = equilibrium_from_demand(P, eq.q_h, eq.q_a, branch)
    assert (again.rho_h, again.rho_a) == pytest.approx((eq.rho_h, eq.rho_a), rel=1e-8)


def test_penetration_helper_recovers_the_base_case():
    base = equilibrium_from_densities(P, 0.110, 0.095)
    eq = equilibrium_at_penetration(P, base.q, base.penetration)
    assert (eq.rho_h, eq.rho_a) == pytest.approx((0.110, 0.095), rel=1e-9)


@pytest.mark.parametrize(("q", "pen", "error", "match"), [
    (veh_h_to_veh_s(20000), 0.5, DemandError, r"flow = 20000 veh/h .* at most \d+ veh/h"),
    (-1.0, 0.5, DemandError, r"flow = -1.0 is not allowed"),
    (1.0, 0.0, ModelError, r"penetration = 0.0 is not allowed: a fraction strictly"),
    (1.0, 0.5, ModelError, r"branch = 'jam' is not allowed"),
])
def test_penetration_helper_errors(q, pen, error, match):
    branch = "jam" if "branch" in match else "congested"
    with pytest.raises(error, match=match):
        equilibrium_at_penetration(P, q, pen, branch)
