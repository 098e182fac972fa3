import numpy as np
import pytest

from arzsumo.errors import ModelError
from arzsumo.model import ModelParameters, get_preset, speed_jacobian
from arzsumo.model.fd import area_occupancy, equilibrium_speeds


@pytest.mark.parametrize(("changes", "match"), [
    ({"vehicle_width": -1.0}, r"vehicle_width = -1.0 .*greater than 0"),
    ({"ao_max_h": 1.2}, r"ao_max_h = 1.2 .*\(0, 1\]"),
    ({"tau_a": float("nan")}, r"tau_a = nan"),
    ({"vehicle_width": 7.0}, r"vehicle_width = 7.0 .*road width"),
    ({"spacing_z": 3.0}, r"unknown model parameter.*spacing_z"),
])
def test_bad_parameters_are_named(changes, match):
    with pytest.raises(ModelError, match=match):
        ModelParameters().with_(**changes)


def test_unknown_preset_lists_the_known_ones():
    with pytest.raises(ModelError, match="paper_base, paper_s12"):
        get_preset("paper_base2")


def test_paper_s12_speeds_match_the_paper_at_d_2m():
    p = get_preset("paper_s12")
    v_h, v_a = equilibrium_speeds(p.params, p.rho_h, p.rho_a)
    assert v_h * 3.6 == pytest.approx(48, abs=0.5)
    assert v_a * 3.6 == pytest.approx(28, abs=0.5)


def test_paper_base_speeds_need_d_2_07():
    p = get_preset("paper_base")
    v_h, v_a = equilibrium_speeds(p.params.with_(vehicle_width=2.07), p.rho_h, p.rho_a)
    assert v_h * 3.6 == pytest.approx(32, abs=0.5)
    assert v_a * 3.6 == pytest.approx(15, abs=0.5)


def test_speed_jacobian_matches_finite_differences():
    p = ModelParameters()
    rho = np.array([[0.11, 0.095], [0.05, 0.02], [0.15, 0.08]])
    jac = speed_jacobian(p, rho[:, 0], rho[:, 1])
    h = 1e-7
    for j in range(2):
        step = np.zeros(2)
        step[j] = h
        up = np.stack(equilibrium_speeds(p, *(rho + step).T), axis=-1)
        dn = np.stack(equilibrium_speeds(p, *(rho - step).T), axis=-1)
        np.testing.assert_allclose(jac[:, :, j], (up - dn) / (2 * h), rtol=1e-6)


def test_area_occupancy_is_weighted_by_impact_area():
    p = ModelParameters(vehicle_width=2.0, spacing_h=8.0, spacing_a=15.0, road_width=6.5)
    assert area_occupancy(p, 0.11, 0.095) == pytest.approx((16 * 0.11 + 30 * 0.095) / 6.5)
