"""Area-occupancy fundamental diagram (paper, section 2, label AOrelation).

Pure vectorised functions of a :class:`ModelParameters` and density arrays (veh/m).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.model.params import ModelParameters


def area_occupancy(p: ModelParameters, rho_h: ArrayLike, rho_a: ArrayLike) -> np.ndarray:
    """AO = (a_h rho_h + a_a rho_a) / W, dimensionless (label AOrelation)."""
    rho_h, rho_a = np.asarray(rho_h, float), np.asarray(rho_a, float)
    return (p.area_h * rho_h + p.area_a * rho_a) / p.road_width


def speed_of_ao(p: ModelParameters, ao: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(Ve_h(AO), Ve_a(AO)) in m/s: V_i (1 - (AO / AO_max_i)^gamma_i)."""
    ao = np.asarray(ao, float)
    ve_h = p.v_free_h * (1.0 - (ao / p.ao_max_h) ** p.gamma_h)
    ve_a = p.v_free_a * (1.0 - (ao / p.ao_max_a) ** p.gamma_a)
    return ve_h, ve_a


def dspeed_dao(p: ModelParameters, ao: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(dVe_h/dAO, dVe_a/dAO) in m/s per unit AO; both are negative for AO > 0."""
    ao = np.asarray(ao, float)
    d_h = -p.v_free_h * p.gamma_h / p.ao_max_h * (ao / p.ao_max_h) ** (p.gamma_h - 1.0)
    d_a = -p.v_free_a * p.gamma_a / p.ao_max_a * (ao / p.ao_max_a) ** (p.gamma_a - 1.0)
    return d_h, d_a


def equilibrium_speeds(p: ModelParameters, rho_h: ArrayLike,
                       rho_a: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """(Ve_h, Ve_a) in m/s at the given class densities (veh/m)."""
    return speed_of_ao(p, area_occupancy(p, rho_h, rho_a))


def speed_jacobian(p: ModelParameters, rho_h: ArrayLike, rho_a: ArrayLike) -> np.ndarray:
    """Partial derivatives of the equilibrium speeds, shape (..., 2, 2), in (m/s)/(veh/m).

    ``out[..., i, j] = dVe_i / drho_j`` with i, j in (h, a). Because Ve_i depends on the
    densities only through AO, ``dVe_i/drho_j = Ve_i'(AO) a_j / W``: the matrix has rank one.
    """
    ao = area_occupancy(p, rho_h, rho_a)
    d_h, d_a = dspeed_dao(p, ao)
    slope = np.stack([d_h, d_a], axis=-1)[..., :, None]            # Ve_i'(AO)
    area = np.array([p.area_h, p.area_a])[None, :] / p.road_width  # a_j / W
    return slope * area
