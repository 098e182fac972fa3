"""Spatial discretisation and one Strang-split time step of the twin: numerical fluxes
between cells (``first``) or MUSCL face values (``muscl``), the boundary fluxes, and forward
Euler (first order) or SSP-RK2 / Heun (MUSCL) for the transport. Vectorised over cells.
"""

from __future__ import annotations

import numpy as np

from arzsumo.model.fd import speed_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.pde.boundary import Inlet, outlet_flux
from arzsumo.pde.flux import FLUXES, LIMITERS, from_reconstruction, muscl_faces, waves
from arzsumo.pde.source import relax
from arzsumo.pde.state import RHO_A, RHO_H, Y_A, Y_H

SCHEMES = ("first", "muscl")


class Transport:
    """Right-hand side -(F_{j+1/2} - F_{j-1/2}) / dx with the boundary fluxes, and one step.

    ``cells`` divide [0, L]; ``flux`` and ``limiter`` (``muscl`` only) are keys of
    :data:`arzsumo.pde.flux.FLUXES` and :data:`arzsumo.pde.flux.LIMITERS`.
    """

    def __init__(self, params: ModelParameters, cells: int, scheme: str, flux: str,
                 limiter: str, inlet: Inlet) -> None:
        self.p = params
        self.dx = params.length / cells
        self.riemann = FLUXES[flux]
        self.limiter = LIMITERS[limiter]
        self.second = scheme == "muscl"
        self.inlet = inlet
        self.limited = False        # outlet demand-limited at the last evaluation
        self._pad = np.empty((4, cells + 2))
        self._full = np.empty((4, cells + 1))

    def _primitive_at(self, r: np.ndarray, j: int) -> np.ndarray:
        """(rho_h, v_h, rho_a, v_a) of cell ``j`` from reconstruction variables ``r``."""
        p = self.p
        rho_h, rho_a = float(r[0, j]), float(r[2, j])
        ve_h, ve_a = speed_of_ao(p, (p.area_h * rho_h + p.area_a * rho_a) / p.road_width)
        return np.array([rho_h, float(r[1, j]) + float(ve_h), rho_a, float(r[3, j]) + float(ve_a)])

    def rhs(self, q: np.ndarray, t: float, outflow: float) -> tuple[np.ndarray, float,
                                                                      float, float]:
        """dq/dt, the largest wave speed (m/s) and the density fluxes in and out (veh/s)."""
        p = self.p
        if self.second:
            n = q.shape[1]
            pad = self._pad                          # (rho_h, w_h, rho_a, w_a) + 2 ghosts
            r = pad[:, 1:-1]
            r[...] = q
            r[Y_H] /= q[RHO_H]
            r[Y_A] /= q[RHO_A]
            # second-order value at x = 0 for the outgoing family: linear extrapolation
            z_b = 1.5 * self._primitive_at(r, 0) - 0.5 * self._primitive_at(r, 1)
            f_in, qb = self.inlet.boundary_flux(p, t, z_b)
            rb = np.array([qb[0], qb[1] / qb[0], qb[2], qb[3] / qb[2]])
            pad[:, 0] = 2.0 * rb - r[:, 0]
            pad[:, -1] = 2.0 * r[:, -1] - r[:, -2]
            east, west = muscl_faces(pad, self.limiter)
            faces = waves(p, from_reconstruction(np.concatenate([east, west], axis=1)))
            flux, smax = self.riemann(faces.sel(slice(0, n - 1)), faces.sel(slice(n + 1, None)))
            out = faces.sel(slice(n - 1, n))
            s = max(float(smax.max()), float(-faces.lo[n]), float(faces.hi[n - 1]))
        else:
            cells = waves(p, q)
            z0 = np.array([q[RHO_H, 0], cells.v_h[0], q[RHO_A, 0], cells.v_a[0]])
            f_in, _ = self.inlet.boundary_flux(p, t, z0)
            flux, smax = self.riemann(cells.sel(slice(None, -1)), cells.sel(slice(1, None)))
            out = cells.sel(slice(-1, None))
            s = max(float(smax.max()), float(-cells.lo[0]), float(cells.hi[-1]))
        f_out, self.limited = outlet_flux(out.q[:, 0], float(out.v_h[0]), float(out.v_a[0]),
                                          outflow, congested=bool(out.lo[0] < 0.0))
        full = self._full
        full[:, 0] = f_in
        full[:, 1:-1] = flux
        full[:, -1] = f_out
        dq = (full[:, :-1] - full[:, 1:]) / self.dx
        return dq, s, float(f_in[RHO_H] + f_in[RHO_A]), float(f_out[RHO_H] + f_out[RHO_A])

    def step(self, q: np.ndarray, t: float, dt: float,
             outflow: float) -> tuple[np.ndarray, float, float, float]:
        """One Strang-split step: relaxation dt/2, transport dt, relaxation dt/2.

        Returns the new q, the largest wave speed met (m/s) and the vehicles that entered
        and left during the step.
        """
        q = relax(self.p, q, 0.5 * dt)
        dq, s1, fin1, fout1 = self.rhs(q, t, outflow)
        q1 = q + dt * dq
        if not self.second:
            return relax(self.p, q1, 0.5 * dt), s1, dt * fin1, dt * fout1
        dq2, s2, fin2, fout2 = self.rhs(q1, t + dt, outflow)
        q2 = 0.5 * (q + q1 + dt * dq2)
        return (relax(self.p, q2, 0.5 * dt), max(s1, s2), 0.5 * dt * (fin1 + fin2),
                0.5 * dt * (fout1 + fout2))


def max_cell_speed(p: ModelParameters, q: np.ndarray) -> float:
    """Largest characteristic speed magnitude over the cells, m/s."""
    w = waves(p, q)
    return float(max(-w.lo.min(), w.hi.max()))
