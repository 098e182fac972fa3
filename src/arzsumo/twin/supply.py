"""A cell's receiving capacity (supply), for an inlet flux limited as in a cell transmission
model.

Daganzo's cell transmission model lets into a cell the smaller of what the upstream cell
would send (its demand) and what the cell can take (its supply); the supply falls to zero
at the jam, so no inflow can push a cell past it. This module gives that supply for the
mixed-autonomy model, in occupancy units, from the model's own diagram.

Occupancy flux. A class-i flow rho_i v_i (veh/s) carries the area occupancy
(a_i / W) rho_i v_i per second across a section (m/s: AO times metres per second; label
AOrelation). A cell at area occupancy AO whose occupancy is shared phi_h : phi_a between
the classes (phi_i = a_i rho_i / (W AO), phi_h + phi_a = 1) carries at equilibrium::

    Phi_e(AO) = AO (phi_h Ve_h(AO) + phi_a Ve_a(AO))

with Ve_i the speed of the model's family (:mod:`arzsumo.model.fd`: eq. (3) for
``power``, the smoothed Newell triangle for ``newell``; the same definition the twin's flux
reads). The supply is the non-increasing envelope of Phi_e from the right::

    S(AO) = max over AO' in [AO, AO_max) of Phi_e(AO')

that is the capacity Phi_max below the critical occupancy and Phi_e(AO) above it
(congestion), with the mix of the receiving cell. It vanishes at AO_max when both classes
share that jam occupancy (where they do not, the class with the larger one still moves at
AO_max, and its share of Phi_e stays positive there).

Limited inlet flux (:meth:`ReceivingCapacity.limit`). The demand is the physical flux f of
the boundary state (the ghost cell), D = sum_i (a_i / W) f_rho_i. Where D > S the whole
flux f is scaled by theta = S / D: each class keeps its share of the entering occupancy
and its vehicles their Lagrangian marker y_i / rho_i (the y-flux scales with the density
flux). Where D <= S the flux is f itself, to the bit. The limit acts at x = 0 only; the
interior scheme and the conservation of vehicles are unchanged (the limited flux is the
flux the stepper counts as inflow).
"""

from __future__ import annotations

import numpy as np

from arzsumo.model.fd import speed_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.twin.state import RHO_A, RHO_H

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
        own = self.equilibrium_flux(rho_h, rho_a)
        return max(own, self._beyond(ao, self._ah * rho_h / ao if ao > 0.0 else 0.5))

    def _beyond(self, ao: float, share_h: float) -> float:
        """Largest Phi_e (m/s) on the grid above ``ao`` with the HV share ``share_h``."""
        k = int(np.searchsorted(self._ao, ao, side="right"))
        if k >= self._ao.size:
            return 0.0
        mix = share_h * self._flux_h[k:] + (1.0 - share_h) * self._flux_a[k:]
        return float(mix.max())

    def limit(self, flux: np.ndarray, rho_h: float, rho_a: float) -> tuple[np.ndarray, float]:
        """The inflow ``flux`` (4,) into a cell with densities ``rho_h``, ``rho_a``, limited
        to the cell's supply.

        Parameters
        ----------
        flux : ndarray, shape (4,)
            The demand: the physical flux (rho_h v_h, y_h v_h, rho_a v_a, y_a v_a) of the
            boundary state, veh/s and veh/s^2.
        rho_h, rho_a : float
            The receiving cell's densities, veh/m.

        Returns
        -------
        flux : ndarray, shape (4,)
            ``flux`` itself where its occupancy demand is within the supply, else
            ``theta * flux``.
        theta : float
            The factor, in [0, 1]; 1.0 where the supply did not bind.
        """
        demand = self._ah * float(flux[RHO_H]) + self._aa * float(flux[RHO_A])
        if demand <= 0.0:
            return flux, 1.0
        rho_h, rho_a = max(float(rho_h), 0.0), max(float(rho_a), 0.0)
        ao = self.occupancy(rho_h, rho_a)
        if ao < self.p.ao_max and demand <= self.equilibrium_flux(rho_h, rho_a):
            return flux, 1.0                       # within S >= Phi_e: no grid needed
        supply = self(rho_h, rho_a)
        if demand <= supply:
            return flux, 1.0
        theta = supply / demand
        return theta * flux, theta
