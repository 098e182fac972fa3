"""An inlet driven by class demand time series, for the tests of the twin and estimators."""

from __future__ import annotations

import numpy as np

from arzsumo.model.characteristic import Linearization
from arzsumo.model.equilibrium import equilibrium_from_demand
from arzsumo.pde import Inlet


def inlet_from_demands(lin: Linearization, times: np.ndarray, demand_h: np.ndarray,
                       demand_a: np.ndarray) -> Inlet:
    """An inlet driven by class demand time series (veh/s at ``times`` s).

    At each sample the inlet densities are those of the congested equilibrium that carries
    the demands; densities and total flow are interpolated linearly between samples and
    held beyond them.
    """
    times = np.asarray(times, float)
    demand_h = np.asarray(demand_h, float)
    demand_a = np.asarray(demand_a, float)
    p = lin.equilibrium.params
    eqs = [equilibrium_from_demand(p, float(qh), float(qa))
           for qh, qa in zip(demand_h, demand_a, strict=True)]
    rho_h = np.array([e.rho_h for e in eqs])
    rho_a = np.array([e.rho_a for e in eqs])
    flow = demand_h + demand_a
    return Inlet(lambda t: float(np.interp(t, times, rho_h)),
                 lambda t: float(np.interp(t, times, rho_a)),
                 lambda t: float(np.interp(t, times, flow)), lin.T[3])
