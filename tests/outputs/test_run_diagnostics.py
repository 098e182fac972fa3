"""The run summary's inlet state and the periods' trigger terms."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from arzsumo.outputs.bridge import inlet_summary


def test_the_inlet_is_the_first_cells_window_mean_in_report_units():
    micro = np.full((4, 4, 3), 7.0)               # periods x (rho_h, v_h, rho_a, v_a) x cells
    micro[:, 0, 0] = [0.05, 0.07, np.nan, 0.06]   # veh/m: a period without a reading
    micro[:, 1, 0] = 5.0                          # m/s
    micro[:, 2, 0] = np.nan                       # no AV passed the first cell
    micro[:, 3, 0] = np.nan
    got = inlet_summary(SimpleNamespace(micro=micro))
    assert got["rho_h_veh_km"] == pytest.approx(60.0)
    assert got["v_h_kmh"] == pytest.approx(18.0)
    assert math.isnan(got["rho_a_veh_km"]) and math.isnan(got["v_a_kmh"])


def test_the_trigger_terms_are_the_logs_per_check_and_nan_without_a_trigger():
    from arzsumo.control.base import ControlLog
    from arzsumo.outputs.bridge import trigger_terms

    log = ControlLog()
    for k in range(4):                          # a triggered law logs V, d, m each check
        log.record(float(k), 0.0, 0.0, k == 0, V=10.0 * k, d=0.1 * k, m=-1.0 * k)
    got = trigger_terms(log, 3)                 # three periods: the fourth check not kept
    np.testing.assert_allclose(got["trigger_energy"], [0.0, 10.0, 20.0])
    np.testing.assert_allclose(got["trigger_hold_error"], [0.0, 0.1, 0.2])
    np.testing.assert_allclose(got["trigger_memory"], [0.0, -1.0, -2.0])
    plain = ControlLog()
    plain.record(0.0, 1.0, 1.0, True)           # backstepping: no trigger
    assert all(np.isnan(v).all() and v.size == 2 for v in trigger_terms(plain, 2).values())
