"""A model whose congested characteristic speed is a measured wave speed.

The identified model of a SUMO stream fits its fields but not the speed at which its
waves travel: on the shipped default lambda_4 = -2.6 km/h where SUMO's fluctuations
travel upstream at about -35 km/h. The kernels' transport times L / |lambda_4| are then
about 14 times too long. :func:`wave_matched` gives the model of the same family that
keeps the equilibrium (both class speeds at the same densities) and moves lambda_4 to a
target, so that a design built from it carries the measured wave speed.

The family: both exponents scaled by one factor k (label AOrelation,
Ve_i = V_i (1 - (AO / AO_max,i)^gamma_i)), each AO_max,i then set so that
Ve_i(AO*) is unchanged: (AO* / AO_max,i)^(k gamma_i) = 1 - v_i* / V_i. At a fixed speed
the slope dVe_i/dAO at AO* is proportional to the exponent, so lambda_4 (the smaller
eigenvalue of the density Jacobian, :func:`~arzsumo.model.characteristic_speeds`)
falls monotonically with k. The price is an AO_max closer to AO*: states SUMO shows
above the new AO_max have no speed in the model.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from arzsumo.errors import ModelError, require
from arzsumo.model.characteristic import characteristic_speeds
from arzsumo.model.fd import area_occupancy, equilibrium_speeds
from arzsumo.model.params import ModelParameters

#: the largest exponent scale factor searched
SCALE_MAX = 50.0


def scaled_exponents(p: ModelParameters, rho_h: float, rho_a: float,
                     k: float) -> ModelParameters:
    """``p`` with both exponents times ``k`` and each AO_max moved so that the equilibrium
    speeds at (``rho_h``, ``rho_a``) (veh/m) are unchanged."""
    require(p.family == "power", "family", p.family,
            "'power' (the exponent scaling is the power law's; the newell family sets "
            "wave_speed_h and wave_speed_a directly)")
    ao = float(area_occupancy(p, rho_h, rho_a))
    v_h, v_a = (float(v) for v in equilibrium_speeds(p, rho_h, rho_a))
    if not (0.0 < v_h < p.v_free_h and 0.0 < v_a < p.v_free_a):
        raise ModelError("the equilibrium must lie strictly between standstill and free "
                         f"speed for both classes (v_h = {v_h:.3g}, v_a = {v_a:.3g} m/s)")
    g_h, g_a = k * p.gamma_h, k * p.gamma_a
    return replace(p, gamma_h=g_h, gamma_a=g_a,
                   ao_max_h=ao / (1.0 - v_h / p.v_free_h) ** (1.0 / g_h),
                   ao_max_a=ao / (1.0 - v_a / p.v_free_a) ** (1.0 / g_a))


def smallest_scale(p: ModelParameters, rho_h: float, rho_a: float) -> float:
    """The smallest exponent scale whose AO_max are occupancies (<= 1, both classes):
    AO_max,i <= 1 iff k >= ln(1 - v_i* / V_i) / (gamma_i ln AO*)."""
    ao = float(area_occupancy(p, rho_h, rho_a))
    v_h, v_a = (float(v) for v in equilibrium_speeds(p, rho_h, rho_a))
    return max(np.log1p(-v_h / p.v_free_h) / (p.gamma_h * np.log(ao)),
               np.log1p(-v_a / p.v_free_a) / (p.gamma_a * np.log(ao)))


def wave_matched(p: ModelParameters, rho_h: float, rho_a: float,
                 lambda_4: float) -> ModelParameters:
    """The model of ``p``'s family (:func:`scaled_exponents`) whose lambda_4 at the
    equilibrium (``rho_h``, ``rho_a``) (veh/m) is ``lambda_4`` (m/s).

    Raises
    ------
    ModelError
        If no exponent scale from :func:`smallest_scale` to :data:`SCALE_MAX` reaches
        ``lambda_4``.
    """
    def lam4(k: float) -> float:
        return float(characteristic_speeds(scaled_exponents(p, rho_h, rho_a, k),
                                           rho_h, rho_a)[3])

    low, high = smallest_scale(p, rho_h, rho_a) * (1.0 + 1e-9), SCALE_MAX
    reach = sorted((lam4(low), lam4(high)))
    if not reach[0] <= lambda_4 <= reach[1]:
        raise ModelError(f"lambda_4 = {lambda_4:.4g} m/s is out of this model family's "
                         f"reach at the equilibrium ({reach[0]:.4g} to {reach[1]:.4g} m/s)")
    return scaled_exponents(p, rho_h, rho_a, brentq(lambda k: lam4(k) - lambda_4, low,
                                                    high, xtol=1e-12))
