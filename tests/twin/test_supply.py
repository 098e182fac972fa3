"""A cell's receiving capacity: the envelope of the model's equilibrium occupancy flux."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.model import PRESETS
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.pde.supply import ReceivingCapacity

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


def test_sending_is_the_flux_below_critical_and_the_capacity_above(params):
    p, cap = params, ReceivingCapacity(params)
    ao = np.linspace(0.005, 0.999 * p.ao_max, 400)
    flux = np.array([cap.equilibrium_flux(*_densities(p, a)) for a in ao])
    sending = np.array([cap.sending(*_densities(p, a)) for a in ao])
    supply = np.array([cap(*_densities(p, a)) for a in ao])
    k = int(np.argmax(flux))
    np.testing.assert_array_equal(sending[:k - 1], flux[:k - 1])   # free flow: exact
    np.testing.assert_allclose(sending[k + 1:], supply[0], rtol=1e-12)   # the capacity
    assert np.all(np.diff(sending) >= -1e-12) and np.all(sending >= flux)


def test_a_congested_sender_demands_the_capacity(params):
    """``sender``: a state at equilibrium above critical sends at capacity into an empty
    cell, and what the receiving cell's supply allows into a congested one."""
    p, cap = params, ReceivingCapacity(params)
    queue = _densities(p, 0.8 * p.ao_max)
    ve_h, ve_a = equilibrium_speeds(p, *queue)
    own = np.array([queue[0] * ve_h, 0.0, queue[1] * ve_a, 0.0])
    capacity = cap(*_densities(p, 0.01))
    out, theta = cap.limit(own, *_densities(p, 0.01), sender=queue)
    assert theta > 1.0
    assert (p.area_h * out[0] + p.area_a * out[2]) / p.road_width == pytest.approx(capacity,
                                                                                  rel=1e-12)
    dense = _densities(p, 0.9 * p.ao_max)
    out, theta = cap.limit(own, *dense, sender=queue)
    assert (p.area_h * out[0] + p.area_a * out[2]) / p.road_width == pytest.approx(
        cap(*dense), rel=1e-12)
    free = _densities(p, 0.1)
    ve_h, ve_a = equilibrium_speeds(p, *free)
    flux = np.array([free[0] * ve_h, 0.0, free[1] * ve_a, 0.0])
    out, theta = cap.limit(flux, *_densities(p, 0.05), sender=free)
    assert out is flux and theta == 1.0                   # a free-flow sender: its flux
