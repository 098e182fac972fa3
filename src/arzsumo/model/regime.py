"""Free/congested regime from the sign of lambda_4 (paper, figure congestedregion)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from arzsumo.model.characteristic import characteristic_speeds
from arzsumo.model.fd import area_occupancy
from arzsumo.model.params import ModelParameters


@dataclass(frozen=True)
class RegimeMap:
    """lambda_4 over a grid of equilibrium densities.

    ``lambda_4[i, j]`` belongs to ``rho_h[j]``, ``rho_a[i]`` (veh/m); it is NaN where the
    equilibrium is infeasible (AO at or above min(ao_max_h, ao_max_a)).
    """

    rho_h: np.ndarray
    rho_a: np.ndarray
    lambda_4: np.ndarray


def regime_map(params: ModelParameters, n: int = 200) -> RegimeMap:
    """lambda_4 on an n x n grid covering every feasible (rho_h*, rho_a*)."""
    rho_h = np.linspace(0.0, params.road_width * params.ao_max / params.area_h, n + 1)[1:]
    rho_a = np.linspace(0.0, params.road_width * params.ao_max / params.area_a, n + 1)[1:]
    hh, aa = np.meshgrid(rho_h, rho_a)
    feasible = area_occupancy(params, hh, aa) < params.ao_max
    lam4 = np.full(hh.shape, np.nan)
    lam4[feasible] = characteristic_speeds(params, hh[feasible], aa[feasible])[:, 3]
    return RegimeMap(rho_h, rho_a, lam4)
