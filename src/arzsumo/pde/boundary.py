"""Boundary conditions of section 2 for the finite-volume twin (docs/twin.md, "Boundary
conditions"); z = (rho_h, v_h, rho_a, v_a).

Inlet (x = 0): rho_i(0, t) = rho_i^in(t) and rho_h v_h + rho_a v_a = q^in(t) (defaults
rho_i*, q_h* + q_a*). The fourth relation keeps the lambda_4 Riemann variable of the first
cell, l_4 . z_b = l_4 . z_0 (l_4 = row 4 of T), a 2x2 linear system for (v_h, v_a) at the
boundary; the inlet flux is the physical flux of z_b, so exactly q^in(t) enters.

Outlet (x = L): rho_h v_h + rho_a v_a = q* + U(t), split in proportion to the class flows
arriving in the last cell, F_rho_i = (q* + U) q_i / (q_h + q_a), each vehicle leaving with
its own marker, F_y_i = (y_i / rho_i) F_rho_i. Where the last cell is congested (lambda_min
< 0) q* + U is imposed, floored at 0; in free flow no condition can be imposed and the
outflow is min(q* + U, q_h + q_a): a meter cannot pull vehicles that are not there.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import ModelError
from arzsumo.model.characteristic import Linearization
from arzsumo.model.fd import speed_of_ao
from arzsumo.model.params import ModelParameters

Signal = float | Callable[[float], float]


def _value(signal: Signal, t: float) -> float:
    return float(signal(t)) if callable(signal) else float(signal)


@dataclass(frozen=True)
class Inlet:
    """Inlet data: class densities (veh/m) and total inflow (veh/s), constants or f(t).

    Parameters
    ----------
    rho_h, rho_a : float or callable
        Inlet class densities rho_i(0, t), veh/m.
    flow : float or callable
        Total inflow rho_h v_h + rho_a v_a at x = 0, veh/s.
    l4 : ndarray, shape (4,)
        Left eigenvector of lambda_4 in z = (rho_h, v_h, rho_a, v_a) (row 4 of T).
    """

    rho_h: Signal
    rho_a: Signal
    flow: Signal
    l4: np.ndarray

    def __post_init__(self) -> None:
        l4 = np.array(self.l4, dtype=float)
        if l4.shape != (4,) or not np.all(np.isfinite(l4)):
            raise ModelError(f"l4 = {self.l4!r} is not allowed: 4 finite numbers")
        l4.setflags(write=False)
        object.__setattr__(self, "l4", l4)
        object.__setattr__(self, "_l4", tuple(float(v) for v in l4))   # hot path

    @classmethod
    def at_equilibrium(cls, lin: Linearization) -> Inlet:
        """The paper's inlet: rho_i(0) = rho_i*, inflow q_h* + q_a*."""
        eq = lin.equilibrium
        return cls(eq.rho_h, eq.rho_a, eq.q, lin.T[3])

    def boundary_primitive(self, t: float, z0: np.ndarray) -> np.ndarray:
        """Boundary state (rho_h, v_h, rho_a, v_a) at x = 0 given the first cell's ``z0``."""
        rho_h, rho_a, flow = _value(self.rho_h, t), _value(self.rho_a, t), _value(self.flow, t)
        l0, l1, l2, l3 = self._l4
        z = [float(v) for v in z0]
        c = l0 * (z[0] - rho_h) + l1 * z[1] + l2 * (z[2] - rho_a) + l3 * z[3]
        det = l1 * rho_a - l3 * rho_h
        if abs(det) < 1e-12 * (abs(l1) + abs(l3)) * (rho_h + rho_a):
            raise ModelError(f"inlet densities ({rho_h:.4g}, {rho_a:.4g}) veh/m make the inlet "
                             "condition singular for the outgoing family lambda_4")
        v_h = (c * rho_a - l3 * flow) / det
        v_a = (l1 * flow - rho_h * c) / det
        return np.array([rho_h, v_h, rho_a, v_a])

    def boundary_flux(self, p: ModelParameters, t: float,
                      z0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Physical flux (4,) of the boundary state at x = 0, and that state (conserved)."""
        rho_h, v_h, rho_a, v_a = self.boundary_primitive(t, z0)
        rho_h, v_h, rho_a, v_a = float(rho_h), float(v_h), float(rho_a), float(v_a)
        ve_h, ve_a = speed_of_ao(p, (p.area_h * rho_h + p.area_a * rho_a) / p.road_width)
        y_h, y_a = rho_h * (v_h - ve_h), rho_a * (v_a - ve_a)
        return (np.array([rho_h * v_h, y_h * v_h, rho_a * v_a, y_a * v_a]),
                np.array([rho_h, y_h, rho_a, y_a]))


def outlet_flux(q_last: np.ndarray, v_h: float, v_a: float, total: float,
                congested: bool = True) -> tuple[np.ndarray, bool]:
    """Flux (4,) through x = L carrying the metered outflow ``total`` = q* + U (veh/s),
    split by the rule above, and whether the arriving demand (or 0), not ``total``, set it.

    ``q_last`` is the conserved state at the outlet face (the last cell, or its
    reconstructed east value), ``v_h``, ``v_a`` the speeds there (m/s), ``congested``
    whether the smallest characteristic speed there is negative.
    """
    rho_h, y_h, rho_a, y_a = (float(c) for c in q_last)
    q_h, q_a = rho_h * v_h, rho_a * v_a
    arriving = q_h + q_a
    share_h = q_h / arriving if arriving > 0 and math.isfinite(arriving) else 0.5
    flow = max(total, 0.0)
    if not congested:
        flow = min(flow, max(arriving, 0.0))
    f_h, f_a = flow * share_h, flow * (1.0 - share_h)
    return np.array([f_h, y_h / rho_h * f_h, f_a, y_a / rho_a * f_a]), flow != total
