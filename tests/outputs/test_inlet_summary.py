"""The inlet's state in the run summary: the first Edie cell's window means, per class."""

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
