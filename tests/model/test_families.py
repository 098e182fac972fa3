"""Fundamental-diagram families: one definition of Ve and Ve', the single-class limit
lambda = Q_e'(rho), Newell's wave speed, and the scenario keys a family does not read."""

from __future__ import annotations

import numpy as np
import pytest
from arzsumo_studies.measures.wave_match import wave_matched

from arzsumo.errors import ModelError, ScenarioError
from arzsumo.model import PRESETS, ModelParameters, characteristic_speeds
from arzsumo.model.fd import area_occupancy, speed_of_ao, speed_terms_of_ao
from arzsumo.model.params import FAMILIES
from arzsumo.scenario import scenario_from_dict
from tests.conftest import NEWELL_CHANGES

POWER = PRESETS["paper_base"].params
NEWELL = POWER.with_(**NEWELL_CHANGES)


def test_every_family_has_one_definition():
    from arzsumo.model import fd

    assert set(fd._FAMILY) == set(FAMILIES)


def test_the_power_family_is_the_papers_eq_3():
    ao = np.linspace(0.0, 0.84, 50)
    ve_h, ve_a = speed_of_ao(POWER, ao)
    np.testing.assert_allclose(ve_h, POWER.v_free_h * (1 - (ao / 0.9) ** 2.5), rtol=1e-14,
                               atol=1e-14)
    np.testing.assert_allclose(ve_a, POWER.v_free_a * (1 - (ao / 0.85) ** 2.0), rtol=1e-14,
                               atol=1e-14)


@pytest.mark.parametrize("params", [POWER, NEWELL, NEWELL.with_(corner=1.0),
                                    NEWELL.with_(corner=2.7, wave_speed_a=20 / 3.6)],
                         ids=["power", "newell", "newell-n1", "newell-n2.7"])
def test_slopes_are_the_derivative_of_the_speeds(params):
    ao = np.linspace(0.02, 0.83, 40)
    _, _, d_h, d_a = speed_terms_of_ao(params, ao)
    h = 1e-7
    up, dn = speed_of_ao(params, ao + h), speed_of_ao(params, ao - h)
    for d, u, w in ((d_h, up[0], dn[0]), (d_a, up[1], dn[1])):
        np.testing.assert_allclose(d, (u - w) / (2 * h), rtol=1e-6, atol=1e-6 * abs(d).max())
    assert (d_h < 0).all() and (d_a < 0).all()


def test_newell_runs_from_free_speed_to_standstill_at_the_jam_occupancy():
    ve_h, _ = speed_of_ao(NEWELL, np.array([0.0, 0.95 * (1 - 1e-12)]))
    _, ve_a = speed_of_ao(NEWELL, np.array([0.0, 0.9 * (1 - 1e-12)]))
    assert ve_h[0] == NEWELL.v_free_h and ve_a[0] == NEWELL.v_free_a
    assert ve_h[1] < 1e-9 and ve_a[1] < 1e-9
    # the smoothed corner lies below both branches, and approaches them away from it
    ao = np.linspace(0.05, 0.89, 30)
    branch = NEWELL.wave_speed_h * (0.95 / ao - 1)
    triangle = np.minimum(NEWELL.v_free_h, branch)
    ve = speed_of_ao(NEWELL, ao)[0]
    assert (ve <= triangle).all()
    assert ve[-1] == pytest.approx(branch[-1], rel=1e-4)
    assert ve[0] == pytest.approx(NEWELL.v_free_h, rel=1e-3)


def _single_class_q_prime(p: ModelParameters, rho: float) -> float:
    """Q_e'(rho) of HVs alone, Q = rho Ve_h(a_h rho / W), by central differences."""
    def q(r: float) -> float:
        return r * float(speed_of_ao(p, area_occupancy(p, r, 0.0))[0])
    h = 1e-8
    return (q(rho + h) - q(rho - h)) / (2 * h)


@pytest.mark.parametrize("params", [POWER, NEWELL], ids=["power", "newell"])
@pytest.mark.parametrize("rho_h", [0.10, 0.16, 0.25])
def test_in_the_single_class_limit_lambda_is_q_e_prime(params, rho_h):
    """With (almost) no AVs the density Jacobian's eigenvalues are the AVs' speed and
    Q_e'(rho) of HVs alone (Fan, Herty & Seibold): lambda_4 where Q_e' < v_a."""
    lam = characteristic_speeds(params, rho_h, 1e-9)
    q_prime = _single_class_q_prime(params, rho_h)
    v_a = float(speed_of_ao(params, area_occupancy(params, rho_h, 0.0))[1])
    np.testing.assert_allclose(sorted([lam[1], lam[3]]), sorted([q_prime, v_a]), rtol=1e-5)
    if q_prime < v_a:
        assert lam[3] == pytest.approx(q_prime, rel=1e-5)


def test_newell_slow_wave_tends_to_minus_w_deep_in_congestion():
    p = NEWELL.with_(corner=8.0)
    rho_jam = 0.9 * p.road_width / p.area_h
    for frac, tol in ((0.6, 0.02), (0.9, 1e-4)):
        lam4 = characteristic_speeds(p, frac * rho_jam, 1e-9)[3]
        assert lam4 == pytest.approx(-p.wave_speed_h, rel=tol)
    # the power law with the same jam occupancy is several times slower there
    lam4_power = characteristic_speeds(POWER.with_(ao_max_h=0.9), 0.6 * rho_jam, 1e-9)[3]
    assert abs(lam4_power) < 0.5 * p.wave_speed_h


def test_newell_mixed_stream_waves_at_w():
    """Both classes on one congested branch (equal w and jam occupancy): lambda_4 = -w."""
    p = PRESETS["paper_base"]
    lam = characteristic_speeds(NEWELL, p.rho_h, p.rho_a)
    assert lam[3] == pytest.approx(-35 / 3.6, rel=2e-3)
    assert lam[0] > 0 and lam[2] > 0


@pytest.mark.parametrize(("changes", "match"), [
    ({"family": "triangle"}, r"family = 'triangle' is not allowed: one of power, newell"),
    ({"family": "newell", "corner": 0.5}, r"corner = 0.5 .*n >= 1"),
    ({"family": "newell", "wave_speed_h": -1.0}, r"wave_speed_h = -1.0"),
])
def test_bad_family_parameters_are_named(changes, match):
    with pytest.raises(ModelError, match=match):
        ModelParameters().with_(**changes)


def test_wave_matching_is_the_power_laws_and_refuses_newell():
    p = PRESETS["paper_base"]
    with pytest.raises(ModelError, match="family = 'newell'"):
        wave_matched(NEWELL, p.rho_h, p.rho_a, -30 / 3.6)


def _scenario(model: dict, equilibrium: dict | None = None):
    return scenario_from_dict({"model": model, "equilibrium": equilibrium or {}}, "x.toml")


def test_a_newell_scenario_reads_its_keys_in_file_units():
    sc = _scenario({"family": "newell", "ao_max_h": 0.9, "ao_max_a": 0.9,
                    "wave_speed_h_kmh": 35, "wave_speed_a_kmh": 30, "corner": 4})
    assert sc.params.family == "newell"
    assert sc.params.wave_speed_h == pytest.approx(35 / 3.6)
    assert sc.params.wave_speed_a == pytest.approx(30 / 3.6)


@pytest.mark.parametrize(("model", "match"), [
    ({"wave_speed_h_kmh": 35},
     r"^x.toml: \[model\] wave_speed_h_kmh = 35 is not read by family = 'power'; allowed: "
     r"omit it, or set family = 'newell'$"),
    ({"family": "newell", "ao_max_h": 0.9, "ao_max_a": 0.9, "gamma_a": 2.0},
     r"^x.toml: \[model\] gamma_a = 2.0 is not read by family = 'newell'"),
    ({"family": "newel"}, r'^x.toml: \[model\] family = "newel" is not allowed: one of '
                          r"power, newell$"),
])
def test_a_key_the_family_does_not_read_is_refused_in_one_line(model, match):
    with pytest.raises(ScenarioError, match=match) as err:
        _scenario(model)
    assert "\n" not in str(err.value)


def test_a_newell_model_without_a_congested_equilibrium_is_refused_naming_the_key():
    """At 30 HV/km and 10 AV/km (AO 0.12) the smoothed triangle is on its free branch."""
    model = {"family": "newell", "ao_max_h": 0.9, "ao_max_a": 0.9}
    with pytest.raises(ScenarioError, match=r"^x.toml: \[model\] family = 'newell' admits no "
                                            r"congested equilibrium at rho_h = 30, rho_a = 10"
                                            r" veh/km .*lambda_4 = \+") as err:
        _scenario(model, {"rho_h_veh_km": 30, "rho_a_veh_km": 10})
    assert "\n" not in str(err.value)
    # the same densities on the power law are accepted (its regime is the map's business)
    assert _scenario({}, {"rho_h_veh_km": 30, "rho_a_veh_km": 10}).equilibrium.ao < 0.2
