"""A batch of first-order twins advanced together: one vectorised step for all members.

The ensemble Kalman filter advances M copies of the twin every period; rather than M
:class:`arzsumo.pde.TwinStepper` objects (M times the Python overhead of a step), the
conserved state carries a member axis, ``q`` of shape (4, M, n) (component, member, cell),
and the twin's first-order scheme (:mod:`arzsumo.pde.scheme`, with the flux functions of
:mod:`arzsumo.pde.flux` as they are) runs once on the whole batch. Boundaries, per member,
are those of the SUMO bridge (:mod:`arzsumo.bridge.twins`): at x = 0 the physical flux of a
primitive ghost state, at x = L the metered outflow of
:func:`arzsumo.pde.boundary.outlet_flux`. All members share the CFL step of the fastest
one, so member k equals a single twin driven to the same step times. A member whose step
leaves the physical domain is projected back onto it (:func:`project`).
"""

from __future__ import annotations

import numpy as np

from arzsumo.model.fd import area_occupancy, speed_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.pde.flux import FLUXES, Waves, waves
from arzsumo.pde.solver import CFL_MAX
from arzsumo.pde.source import relax
from arzsumo.pde.state import RHO_A, RHO_H, cell_centres, to_conserved, to_primitive


def ghost_flux(p: ModelParameters, ghost: np.ndarray) -> np.ndarray:
    """Physical flux (4, M) of primitive ghost states (4, M) at x = 0: the arithmetic of
    :meth:`arzsumo.pde.boundary.Inlet.boundary_flux`."""
    rho_h, v_h, rho_a, v_a = ghost
    ve_h, ve_a = speed_of_ao(p, area_occupancy(p, rho_h, rho_a))
    y_h, y_a = rho_h * (v_h - ve_h), rho_a * (v_a - ve_a)
    return np.stack([rho_h * v_h, y_h * v_h, rho_a * v_a, y_a * v_a])


def outlet_fluxes(out: Waves, total: np.ndarray) -> np.ndarray:
    """Outlet flux (4, M) of :func:`arzsumo.pde.boundary.outlet_flux` per member, from the
    last cell of each (``out``) and the metered outflow q* + U of each (``total``, veh/s)."""
    rho_h, y_h, rho_a, y_a = out.q
    q_h, q_a = rho_h * out.v_h, rho_a * out.v_a
    arriving = q_h + q_a
    with np.errstate(invalid="ignore", divide="ignore"):
        share_h = np.where((arriving > 0) & np.isfinite(arriving), q_h / arriving, 0.5)
    flow = np.maximum(total, 0.0)
    flow = np.where(out.lo < 0.0, flow, np.minimum(flow, np.maximum(arriving, 0.0)))
    f_h, f_a = flow * share_h, flow * (1.0 - share_h)
    return np.stack([f_h, y_h / rho_h * f_h, f_a, y_a / rho_a * f_a])


def project(p: ModelParameters, z: np.ndarray, rho_min: float = 1e-4,
            ao_fraction: float = 0.98) -> np.ndarray:
    """Primitive fields (4, ...) moved onto the physical domain; returns a new array.

    Densities at least ``rho_min`` (veh/m); where AO exceeds ``ao_fraction`` AO_max both
    densities are scaled down to it; speeds clipped to [0, V_i] (m/s). Non-finite values
    become the bounds' nearest (0 speed, ``rho_min``).
    """
    z = np.nan_to_num(np.array(z, float), nan=0.0, posinf=0.0, neginf=0.0)
    z[[0, 2]] = np.maximum(z[[0, 2]], rho_min)
    z[[0, 2]] *= np.minimum(1.0, ao_fraction * p.ao_max / area_occupancy(p, z[0], z[2]))
    z[1] = np.clip(z[1], 0.0, p.v_free_h)
    z[3] = np.clip(z[3], 0.0, p.v_free_a)
    return z


def outside(p: ModelParameters, q: np.ndarray) -> np.ndarray:
    """Members (M,) with a cell outside the domain: not finite, density <= 0, AO >= AO_max."""
    with np.errstate(invalid="ignore"):
        ao = area_occupancy(p, q[RHO_H], q[RHO_A])
        bad = ~np.isfinite(q).all(axis=0) | (q[RHO_H] <= 0) | (q[RHO_A] <= 0) | (ao >= p.ao_max)
    return bad.any(axis=-1)


class BatchStepper:
    """First-order twin scheme for a batch of members, q of shape (4, M, n), on ``cells``
    cells of [0, L] with target Courant number ``cfl`` in (0, 1]."""

    def __init__(self, params: ModelParameters, cells: int, flux: str = "hll",
                 cfl: float = 0.9) -> None:
        self.p, self.cells, self.cfl = params, cells, cfl
        self.dx = params.length / cells
        self.riemann = FLUXES[flux]
        self.x = cell_centres(params.length, cells)
        self.steps = self.projected = 0
        self.last_speed: float | None = None     # largest wave speed of the last step, m/s

    def rhs(self, q: np.ndarray, ghost: np.ndarray, outflow: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
        """dq/dt (4, M, n) and the largest wave speed of each member (M,), m/s."""
        cells = waves(self.p, q)
        flux, smax = self.riemann(cells.sel(slice(None, -1)), cells.sel(slice(1, None)))
        s = np.maximum(np.maximum(smax.max(axis=-1), -cells.lo[:, 0]), cells.hi[:, -1])
        full = np.empty((*q.shape[:2], q.shape[2] + 1))
        full[..., 0] = ghost_flux(self.p, ghost)
        full[..., 1:-1] = flux
        full[..., -1] = outlet_fluxes(Waves(*(a[..., -1] for a in cells)), outflow)
        return (full[..., :-1] - full[..., 1:]) / self.dx, s

    def step(self, q: np.ndarray, dt: float, ghost: np.ndarray, outflow: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
        """One Strang-split step of ``dt`` s with primitive inlet states ``ghost`` (4, M) and
        ``outflow`` (M,) veh/s: the new q and the largest wave speed of each member (M,)."""
        q = relax(self.p, q, 0.5 * dt)
        dq, s = self.rhs(q, ghost, outflow)
        return relax(self.p, q + dt * dq, 0.5 * dt), s

    def max_speed(self, q: np.ndarray) -> np.ndarray:
        """Largest characteristic speed magnitude of each member (M,), m/s."""
        w = waves(self.p, q)
        return np.maximum(-w.lo.min(axis=-1), w.hi.max(axis=-1))

    def advance(self, q: np.ndarray, t: float, t_end: float, ghost: np.ndarray,
                outflow: np.ndarray, smax: float | None = None
                ) -> tuple[np.ndarray, float, list[float]]:
        """Advance the batch from ``t`` to ``t_end`` (s) with boundary data held.

        ``smax`` is the wave speed (m/s) that sets the first step (default: that of
        ``q``; a step that turns out faster than Courant 1 is redone). Returns the new q,
        the time reached and the step end times; :attr:`last_speed` keeps the largest wave
        speed of the last step. Members that leave the domain are projected back (:func:`project`).
        """
        eps = 1e-12 * max(1.0, abs(t_end))
        s_prev = float(self.max_speed(q).max()) if smax is None else smax
        times: list[float] = []
        with np.errstate(all="ignore"):
            while t < t_end - eps:
                dt = min(self.cfl * self.dx / max(s_prev, 1e-12), t_end - t)
                while True:
                    t_new = t_end if abs(t + dt - t_end) <= eps else t + dt
                    q_new, s = self.step(q, t_new - t, ghost, outflow)
                    s_step = float(s.max())
                    if s_step * (t_new - t) <= CFL_MAX * self.dx * (1 + 1e-12) or dt < 1e-9:
                        break
                    dt = self.cfl * self.dx / s_step
                bad = outside(self.p, q_new)
                if bad.any():
                    self.projected += int(bad.sum())
                    q_new[:, bad] = to_conserved(self.p, *project(
                        self.p, to_primitive(self.p, q_new[:, bad])))
                q, t, s_prev = q_new, t_new, s_step
                times.append(t)
                self.steps += 1
        self.last_speed = s_prev
        return q, t, times
