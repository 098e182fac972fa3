"""A cell's receiving capacity: the envelope of the model's equilibrium occupancy flux."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.model import PRESETS
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.twin.supply import ReceivingCapacity

#: equal jam occupancies (as the two-stage identification gives them)
NEWELL = {"family": "newell", "ao_max_h": 0.6728, "ao_max_a": 0.6728,
          "wave_speed_h": 33.2 / 3.6, "wave_speed_a": 32.3 / 3.6, "corner": 6.0}


@pytest.fixture(params=["power", "newell"])
def params(request):
    p = PRESETS["paper_base"].params
    return p.with_(ao_max_a=p.ao_max_h) if request.param == "power" else p.with_(**NEWELL)


def _densities(p, ao, share_a=0.3):
    """(rho_h, rho_a) veh/m at occupancy ``ao`` with the AVs' share ``share_a`` of it."""
    return ((1 - share_a) * ao * p.road_width / p.area_h,
            share_a * ao * p.road_width / p.area_a)


def test_equilibrium_flux_is_the_occupancy_of_the_class_flows(params):
    p, cap = params, ReceivingCapacity(params)
    rho_h, rho_a = _densities(p, 0.4)
    ve_h, ve_a = equilibrium_speeds(p, rho_h, rho_a)
    expected = (p.area_h * rho_h * ve_h + p.area_a * rho_a * ve_a) / p.road_width
    assert cap.equilibrium_flux(rho_h, rho_a) == pytest.approx(float(expected), rel=1e-14)


def test_supply_is_capacity_below_critical_and_the_flux_above(params):
    p, cap = params, ReceivingCapacity(params)
    ao = np.linspace(0.005, 0.999 * p.ao_max, 400)
    flux = np.array([cap.equilibrium_flux(*_densities(p, a)) for a in ao])
    supply = np.array([cap(*_densities(p, a)) for a in ao])
    fine = np.linspace(1e-6, p.ao_max * (1 - 1e-9), 200_001)
    capacity = max(cap.equilibrium_flux(*_densities(p, a)) for a in fine[::50])
    k = int(np.argmax(flux))
    assert 0 < k < ao.size - 1                           # a peak inside: both branches
    np.testing.assert_allclose(supply[:k], capacity, rtol=2e-5)
    np.testing.assert_array_equal(supply[k + 2:], flux[k + 2:])   # congested: exact
    assert np.all(np.diff(supply) <= 1e-12)                       # non-increasing
    assert np.all(supply >= flux)
    assert supply[-1] < 1e-2 * capacity                  # vanishes at the jam
    assert cap(*_densities(p, p.ao_max)) == 0.0 == cap(*_densities(p, 1.2 * p.ao_max))


def test_limit_leaves_a_flux_within_the_supply_untouched(params):
    p, cap = params, ReceivingCapacity(params)
    flux = np.array([0.2, 0.01, 0.05, -0.002])
    for ao in (0.1, 0.3, 0.5):
        out, theta = cap.limit(flux, *_densities(p, ao))
        assert out is flux and theta == 1.0


def test_limit_scales_every_class_to_the_supply(params):
    p, cap = params, ReceivingCapacity(params)
    rho_h, rho_a = _densities(p, 0.98 * p.ao_max)
    platoon = np.array([0.6, 2.0, 0.2, 0.5])               # an arriving platoon's flux
    capacity = cap(*_densities(p, 0.01))
    flux = platoon * capacity / ((p.area_h * 0.6 + p.area_a * 0.2) / p.road_width)
    out, theta = cap.limit(flux, rho_h, rho_a)
    supply = cap(rho_h, rho_a)
    assert 0.0 < theta < 0.2
    np.testing.assert_allclose(out, theta * flux, rtol=0, atol=0)
    occupancy = (p.area_h * out[0] + p.area_a * out[2]) / p.road_width
    assert occupancy == pytest.approx(supply, rel=1e-13)
