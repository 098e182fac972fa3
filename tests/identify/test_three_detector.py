"""Newell's three-detector method on cases whose LWR solution is known in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.identify import IdentifyError, ReplayData
from arzsumo.identify.three_detector import Triangle, three_detector_fields

V_FREE, W, RHO_JAM = 25.0, 8.0, 0.15          # m/s, m/s, veh/m
CELLS, DX, PERIODS, DT = 40, 25.0, 120, 1.0   # a 1 km section, 2 min
X = (np.arange(CELLS) + 0.5) * DX
T = (np.arange(PERIODS) + 1.0) * DT
TINY = 1e-9                                  # an AV share the data accept as none


def _data(rho: float, v: float, share: float, inflow: float, outflow: np.ndarray) -> ReplayData:
    """A uniform initial state (rho veh/m at v m/s, AV share ``share``), a constant
    inflow and the given outflow per period."""
    state = np.array([rho * (1 - share), v, rho * share, v])
    fields = np.repeat(state[None, :, None], PERIODS, 0).repeat(CELLS, 2)
    inlet_rho = inflow / v
    inlet = np.tile([inlet_rho * (1 - share), v, inlet_rho * share, v], (PERIODS, 1))
    return ReplayData.from_arrays(T, X, fields, np.repeat(state[:, None], CELLS, 1),
                                  inlet, outflow)


def test_a_stationary_congested_state_is_its_own_solution() -> None:
    fd = Triangle(V_FREE, W, RHO_JAM)
    rho = 0.1                                   # congested: above rho_crit = 0.036
    q = W * (RHO_JAM - rho)
    out = three_detector_fields(_data(rho, q / rho, 0.2, q, np.full(PERIODS, q)), fd)
    np.testing.assert_allclose(out[:, 0], 0.8 * rho, rtol=1e-9)
    np.testing.assert_allclose(out[:, 2], 0.2 * rho, rtol=1e-9)
    assert np.isnan(out[:, [1, 3]]).all()


def test_a_queue_entering_downstream_is_the_shock_of_lwr() -> None:
    """Free flow rho1 meets an outflow cut to q2 at t = 0: a shock from x = L at the
    Rankine-Hugoniot speed (q2 - q1) / (rho2 - rho1), rho2 on the congested branch."""
    fd = Triangle(V_FREE, W, RHO_JAM)
    rho1 = 0.02
    q1, q2 = V_FREE * rho1, 0.3
    rho2 = RHO_JAM - q2 / W
    shock = (q2 - q1) / (rho2 - rho1)                        # m/s, < 0
    out = three_detector_fields(_data(rho1, V_FREE, TINY, q1, np.full(PERIODS, q2)), fd)
    front = X[-1] + DX / 2 + shock * T                       # the shock's position
    upstream = X[None, :] + DX / 2 <= front[:, None]         # cells wholly behind it
    downstream = X[None, :] - DX / 2 >= front[:, None]
    np.testing.assert_allclose(out[:, 0][upstream], rho1, rtol=1e-6)
    np.testing.assert_allclose(out[:, 0][downstream], rho2, rtol=1e-6)
    # the cell the shock is in holds the vehicles of both sides: what entered minus left
    held = out[:, 0].sum(axis=1) * DX
    np.testing.assert_allclose(held, rho1 * 1000.0 + (q1 - q2) * T, rtol=1e-6)


def test_classes_travel_with_their_vehicles() -> None:
    """AVs only in the vehicles that enter: the AV density is the inflow's share behind
    the first entered vehicle (which moves at v_free) and 0 ahead of it."""
    fd = Triangle(V_FREE, W, RHO_JAM)
    rho = 0.02
    q = V_FREE * rho
    data = _data(rho, V_FREE, TINY, q, np.full(PERIODS, q))
    inlet = data.inlet.copy()
    inlet[:, 0], inlet[:, 2] = 0.5 * rho, 0.5 * rho
    data = ReplayData.from_arrays(T, X, data.fields, data.initial, inlet, data.outflow)
    out = three_detector_fields(data, fd)
    k = 20                                                    # t = 21 s: front at 525 m
    front = V_FREE * T[k]
    np.testing.assert_allclose(out[k, 2][front >= X + DX / 2], 0.5 * rho, rtol=1e-9)
    np.testing.assert_allclose(out[k, 2][front <= X - DX / 2], 0.0, atol=1e-9)


@pytest.mark.parametrize("field, value", [("v_free", 0.0), ("w", -8.0), ("rho_jam", np.nan)])
def test_a_triangle_checks_itself(field: str, value: float) -> None:
    args = {"v_free": V_FREE, "w": W, "rho_jam": RHO_JAM, field: value}
    with pytest.raises(IdentifyError, match=field):
        Triangle(**args)


def test_the_triangle_through_an_operating_point() -> None:
    fd = Triangle.through(V_FREE, W, rho=0.1, q=0.4)
    assert fd.rho_jam == pytest.approx(0.15)
    assert fd.capacity == pytest.approx(V_FREE * W * 0.15 / (V_FREE + W))
