"""A cell's receiving capacity (supply), for an inlet flux limited as in Daganzo's cell
transmission model (docs/identify.md, "The inlet").

In occupancy units (m/s; label AOrelation) a cell at AO with class shares phi_i = a_i rho_i
/ (W AO) carries at equilibrium Phi_e(AO) = AO (phi_h Ve_h(AO) + phi_a Ve_a(AO)), with the
family's Ve_i (:mod:`arzsumo.model.fd`). The supply is its non-increasing envelope from the
right, S(AO) = max over AO' in [AO, AO_max) of Phi_e(AO'), the demand (sending function)
its non-decreasing envelope from the left, D_e(AO) = max over AO' in (0, AO] of Phi_e(AO'),
both at the cell's mix. S vanishes at AO_max when both classes share that jam occupancy.

:meth:`ReceivingCapacity.limit` scales the boundary state's whole flux f by theta =
min(demand, S) / F, F = sum_i (a_i / W) f_rho_i, so each class keeps its share and its
vehicles their marker; where min(demand, S) = F it returns f itself, to the bit. The demand
is F, or with ``sender`` F D_e / Phi_e at the boundary state. Only x = 0 is limited: the
interior scheme and the conservation of vehicles are unchanged.
"""

from __future__ import annotations

import numpy as np

from arzsumo.model.fd import speed_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.pde.state import RHO_A, RHO_H

#: points of the occupancy grid on (0, AO_max) the envelope's maximum is taken over
GRID_POINTS = 512


class ReceivingCapacity:
    """The supply S(AO) of a cell of the model ``params`` (module docstring).

    Parameters
    ----------
    params : ModelParameters
    points : int
        Grid points on (0, AO_max) for the maximum below the critical occupancy: where
        the cell is in free flow, S is the grid's largest Phi_e at or above the cell's
        AO (with 512 points the capacity is exact to about 1e-5 of itself; above the
        critical occupancy S = Phi_e(AO) exactly).

    Notes
    -----
    A supply-limited inflow cannot fill the first cell beyond AO_max on its own: near
    the jam Phi_e(AO) <= w (AO_max - AO), with w the congested branch's wave speed
    magnitude (the Newell ``wave_speed_i``; V_i gamma_i for eq. (3)), so a step whose
    Courant number for w is at most 1 and whose flux out of the cell is not negative
    keeps AO <= AO_max (the argument of the cell transmission model).
    """

    def __init__(self, params: ModelParameters, points: int = GRID_POINTS) -> None:
        self.p = params
        self._ah = params.area_h / params.road_width
        self._aa = params.area_a / params.road_width
        ao = np.linspace(0.0, params.ao_max, points + 2)[1:-1]
        ve_h, ve_a = speed_of_ao(params, ao)
        self._ao = ao
        self._flux_h = ao * ve_h                   # Phi_e of an all-HV cell, m/s
        self._flux_a = ao * ve_a                   # Phi_e of an all-AV cell, m/s

    def occupancy(self, rho_h: float, rho_a: float) -> float:
        """AO of class densities (veh/m), label AOrelation."""
        return self._ah * rho_h + self._aa * rho_a

    def equilibrium_flux(self, rho_h: float, rho_a: float) -> float:
        """Phi_e (m/s) of a cell with densities ``rho_h``, ``rho_a`` (veh/m) below AO_max:
        sum_i (a_i / W) rho_i Ve_i(AO)."""
        ve_h, ve_a = speed_of_ao(self.p, self.occupancy(rho_h, rho_a))
        return float(self._ah * rho_h * ve_h + self._aa * rho_a * ve_a)

    def __call__(self, rho_h: float, rho_a: float) -> float:
        """S (m/s) of a cell with densities ``rho_h``, ``rho_a`` (veh/m); 0 at or beyond
        AO_max."""
        rho_h, rho_a = max(float(rho_h), 0.0), max(float(rho_a), 0.0)
        ao = self.occupancy(rho_h, rho_a)
        if ao >= self.p.ao_max:
            return 0.0
        share_h = self._ah * rho_h / ao if ao > 0.0 else 0.5
        return max(self.equilibrium_flux(rho_h, rho_a), self._largest(ao, share_h, above=True))

    def sending(self, rho_h: float, rho_a: float) -> float:
        """D_e (m/s) of a cell with densities ``rho_h``, ``rho_a`` (veh/m): Phi_e in free
        flow, the capacity at its mix in congestion (and at or beyond AO_max)."""
        rho_h, rho_a = max(float(rho_h), 0.0), max(float(rho_a), 0.0)
        ao = self.occupancy(rho_h, rho_a)
        share_h = self._ah * rho_h / ao if ao > 0.0 else 0.5
        if ao >= self.p.ao_max:
            return self._largest(self.p.ao_max, share_h, above=False)
        return max(self.equilibrium_flux(rho_h, rho_a), self._largest(ao, share_h, above=False))

    def _largest(self, ao: float, share_h: float, above: bool) -> float:
        """Largest Phi_e (m/s) on the grid above ``ao`` (or at or below it) with the HV
        share ``share_h``; 0 where that part of the grid is empty."""
        k = int(np.searchsorted(self._ao, ao, side="right"))
        part = slice(k, None) if above else slice(None, k)
        mix = share_h * self._flux_h[part] + (1.0 - share_h) * self._flux_a[part]
        return float(mix.max()) if mix.size else 0.0

    def limit(self, flux: np.ndarray, rho_h: float, rho_a: float,
              sender: tuple[float, float] | None = None) -> tuple[np.ndarray, float]:
        """The inflow ``flux`` (4,) into a cell with densities ``rho_h``, ``rho_a``, limited
        to the cell's supply (and, with ``sender``, raised to a congested sender's demand).

        ``flux`` is the boundary state's physical flux (veh/s and veh/s^2), ``rho_h``,
        ``rho_a`` the receiving cell's densities and ``sender`` the boundary state's (veh/m).
        Returns ``flux`` itself and 1.0 where neither the supply nor the sender's demand
        changes it, else ``theta * flux`` and theta (>= 0).
        """
        carried = self._ah * float(flux[RHO_H]) + self._aa * float(flux[RHO_A])
        if carried <= 0.0:
            return flux, 1.0
        demand = carried if sender is None else carried * self._raise(*sender)
        rho_h, rho_a = max(float(rho_h), 0.0), max(float(rho_a), 0.0)
        ao = self.occupancy(rho_h, rho_a)
        if ao < self.p.ao_max and demand <= self.equilibrium_flux(rho_h, rho_a):
            entering = demand                      # within S >= Phi_e: no grid needed
        else:
            entering = min(demand, self(rho_h, rho_a))
        if entering == carried:
            return flux, 1.0
        theta = entering / carried
        return theta * flux, theta

    def _raise(self, rho_h: float, rho_a: float) -> float:
        """D_e / Phi_e of a sender with densities ``rho_h``, ``rho_a``: exactly 1.0 in free
        flow, the capacity over its own flux in congestion."""
        own = self.equilibrium_flux(rho_h, rho_a) if self.occupancy(rho_h, rho_a) < \
            self.p.ao_max else 0.0
        sending = self.sending(rho_h, rho_a)
        if sending <= own:
            return 1.0
        return sending / own if own > 0.0 else float("inf")
