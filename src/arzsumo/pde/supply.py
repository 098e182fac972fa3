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

The sending function (demand) is the mirror image, the non-decreasing envelope from the
left: D_e(AO) = max over AO' in (0, AO] of Phi_e(AO'), Phi_e(AO) in free flow and the
capacity in congestion (a queue sends at capacity).

Limited inlet flux (:meth:`ReceivingCapacity.limit`). The boundary state (the ghost cell)
carries the physical flux f, in occupancy units F = sum_i (a_i / W) f_rho_i. Its demand
is F itself or, with ``sender`` (the cell transmission model's sending side), F D_e / Phi_e
at the boundary state's occupancy and mix: F in free flow, raised to the capacity times
the state's departure from the diagram in congestion. The flux entering is min(demand, S):
where that differs from F the whole flux f is scaled by theta = min(demand, S) / F, so
each class keeps its share of the entering occupancy and its vehicles their Lagrangian
marker y_i / rho_i (the y-flux scales with the density flux). Where it does not, the flux
is f itself, to the bit. The limit acts at x = 0 only; the interior scheme and the
conservation of vehicles are unchanged (the limited flux is the flux the stepper counts as
inflow).
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
        own = self.equilibrium_flux(rho_h, rho_a)
        return max(own, self._beyond(ao, self._ah * rho_h / ao if ao > 0.0 else 0.5))

    def sending(self, rho_h: float, rho_a: float) -> float:
        """D_e (m/s) of a cell with densities ``rho_h``, ``rho_a`` (veh/m): Phi_e in free
        flow, the capacity at its mix in congestion (and at or beyond AO_max)."""
        rho_h, rho_a = max(float(rho_h), 0.0), max(float(rho_a), 0.0)
        ao = self.occupancy(rho_h, rho_a)
        share_h = self._ah * rho_h / ao if ao > 0.0 else 0.5
        if ao >= self.p.ao_max:
            return self._below(self.p.ao_max, share_h)
        return max(self.equilibrium_flux(rho_h, rho_a), self._below(ao, share_h))

    def _beyond(self, ao: float, share_h: float) -> float:
        """Largest Phi_e (m/s) on the grid above ``ao`` with the HV share ``share_h``."""
        k = int(np.searchsorted(self._ao, ao, side="right"))
        if k >= self._ao.size:
            return 0.0
        mix = share_h * self._flux_h[k:] + (1.0 - share_h) * self._flux_a[k:]
        return float(mix.max())

    def _below(self, ao: float, share_h: float) -> float:
        """Largest Phi_e (m/s) on the grid at or below ``ao`` with the HV share ``share_h``."""
        k = int(np.searchsorted(self._ao, ao, side="right"))
        if k == 0:
            return 0.0
        mix = share_h * self._flux_h[:k] + (1.0 - share_h) * self._flux_a[:k]
        return float(mix.max())

    def limit(self, flux: np.ndarray, rho_h: float, rho_a: float,
              sender: tuple[float, float] | None = None) -> tuple[np.ndarray, float]:
        """The inflow ``flux`` (4,) into a cell with densities ``rho_h``, ``rho_a``, limited
        to the cell's supply (and, with ``sender``, raised to a congested sender's demand).

        Parameters
        ----------
        flux : ndarray, shape (4,)
            The physical flux (rho_h v_h, y_h v_h, rho_a v_a, y_a v_a) of the boundary
            state, veh/s and veh/s^2.
        rho_h, rho_a : float
            The receiving cell's densities, veh/m.
        sender : (float, float), optional
            The boundary state's densities (veh/m): its demand is then the flux times
            D_e / Phi_e there (module docstring); without it, the flux.

        Returns
        -------
        flux : ndarray, shape (4,)
            ``flux`` itself where the demand is the flux and within the supply, else
            ``theta * flux``.
        theta : float
            The factor (>= 0); 1.0 where neither the supply nor the sender's demand
            changed the flux.
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
