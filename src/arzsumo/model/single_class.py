"""The classic single-class ARZ model (2x2) in the same characteristic form (n = 1).

Used to check that the kernel solver handles general n and to compare with the
literature (Yu and Krstic, 2019). Model: rho_t + (rho v)_x = 0,
(v - Ve(rho))_t + v (v - Ve(rho))_x = (Ve(rho) - v) / tau with
Ve(rho) = V (1 - (rho / rho_max)^gamma).

Linearised at (rho*, v* = Ve(rho*)), the characteristic speeds are lambda_1 = v* (the
Lagrangian marker w_1 = v~ - Ve'(rho*) rho~) and lambda_2 = v* + rho* Ve'(rho*) (w_2 = v~),
both rows normalised like the mixed model (speed coefficient one). Then
J_hat = [[-1/tau, 0], [-1/tau, 0]]; inlet rho~ = 0 and zero flow deviation, outlet
v* rho~ + rho* v~ = U.
"""

from __future__ import annotations

import numpy as np

from arzsumo.errors import ModelError
from arzsumo.model.characteristic import CharacteristicSystem


def single_class_arz(v_free: float, rho_max: float, gamma: float, tau: float, rho: float,
                     length: float, inlet: str = "flow") -> CharacteristicSystem:
    """Characteristic form of the linearised single-class ARZ model.

    Parameters
    ----------
    v_free : float
        Free-flow speed V, m/s.
    rho_max, rho : float
        Maximum and equilibrium density, veh/m.
    gamma, tau : float
        Pressure exponent and relaxation time (s).
    length : float
        Road length, m.
    inlet : {"flow", "reflecting-free"}
        "flow": constant inflow (rho~(0) v* + rho* v~(0) = 0), as in the mixed model;
        "reflecting-free": Q = 0 (w+(0) = 0), which has a closed-form kernel.
    """
    v = v_free * (1 - (rho / rho_max) ** gamma)
    dve = -v_free * gamma / rho_max * (rho / rho_max) ** (gamma - 1)
    lam = np.array([v, v + rho * dve])
    if lam[1] >= 0:
        raise ModelError(f"rho = {rho} veh/m is not allowed: the single-class equilibrium must "
                         "be congested (v* + rho* Ve'(rho*) < 0)")
    t = np.array([[-dve, 1.0], [0.0, 1.0]])
    t_inv = np.linalg.inv(t)
    b = np.array([[0.0, 0.0], [dve / tau, -1.0 / tau]])
    j_hat = t @ b @ t_inv
    kappa = np.array([v, rho]) @ t_inv
    if inlet == "flow":
        # one downstream-travelling state, hence one inlet condition: kappa . w(0) = 0
        q = np.array([-kappa[1] / kappa[0]])
    elif inlet == "reflecting-free":
        q = np.zeros(1)
    else:
        raise ModelError(f"inlet = {inlet!r} is not allowed: 'flow' or 'reflecting-free'")
    rate = np.diag(j_hat) / lam
    r = np.array([-(kappa[0] / kappa[1]) * np.exp((rate[0] - rate[1]) * length)])
    return CharacteristicSystem(lam, j_hat, q, r, length)
