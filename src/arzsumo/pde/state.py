"""Conservative state of the nonlinear 4x4 model and its conversions (paper, section 2).

Conserved q = (rho_h, y_h, rho_a, y_a), shape (4, n_cells), in veh/m, veh/s, veh/m, veh/s,
with the ARZ variable y_i = rho_i (v_i - Ve_i(AO)) (docs/twin.md, "Conservation form");
primitive fields (rho_h, v_h, rho_a, v_a) in veh/m and m/s. Pure vectorised functions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.control.base import MacroState
from arzsumo.errors import ModelError
from arzsumo.model.fd import area_occupancy, speed_of_ao
from arzsumo.model.params import ModelParameters

#: Names of the conserved components, in storage order.
CONSERVED = ("rho_h", "y_h", "rho_a", "y_a")

RHO_H, Y_H, RHO_A, Y_A = 0, 1, 2, 3


def speeds(p: ModelParameters, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Class speeds v_i = y_i / rho_i + Ve_i(AO), m/s, from conserved ``q`` (4, ...);
    densities must be positive."""
    ve_h, ve_a = speed_of_ao(p, area_occupancy(p, q[RHO_H], q[RHO_A]))
    return q[Y_H] / q[RHO_H] + ve_h, q[Y_A] / q[RHO_A] + ve_a


def to_conserved(p: ModelParameters, rho_h: ArrayLike, v_h: ArrayLike, rho_a: ArrayLike,
                 v_a: ArrayLike) -> np.ndarray:
    """Conserved q = (rho_h, y_h, rho_a, y_a), shape (4, n), from primitive fields.

    Densities in veh/m, speeds in m/s; y_i = rho_i (v_i - Ve_i(AO)) in veh/s.
    """
    rho_h, v_h, rho_a, v_a = np.broadcast_arrays(*(np.asarray(a, float)
                                                  for a in (rho_h, v_h, rho_a, v_a)))
    ve_h, ve_a = speed_of_ao(p, area_occupancy(p, rho_h, rho_a))
    return np.stack([rho_h, rho_h * (v_h - ve_h), rho_a, rho_a * (v_a - ve_a)])


def to_primitive(p: ModelParameters, q: np.ndarray) -> np.ndarray:
    """Primitive (rho_h, v_h, rho_a, v_a), shape (4, ...), from conserved ``q``."""
    v_h, v_a = speeds(p, q)
    return np.stack([q[RHO_H], v_h, q[RHO_A], v_a])


def cell_centres(length: float, cells: int) -> np.ndarray:
    """Centres (m) of ``cells`` equal cells on [0, length]."""
    if cells < 2:
        raise ModelError(f"cells = {cells!r} is not allowed: at least 2")
    return (np.arange(cells) + 0.5) * (length / cells)


def macro_state(p: ModelParameters, t: float, x: np.ndarray, q: np.ndarray) -> MacroState:
    """The :class:`MacroState` handed to controllers at time ``t`` (s)."""
    v_h, v_a = speeds(p, q)
    return MacroState(float(t), x, q[RHO_H].copy(), v_h, q[RHO_A].copy(), v_a)


def total_vehicles(q: np.ndarray, dx: float) -> float:
    """Vehicles on the road, sum_i sum_cells rho_i dx (veh)."""
    return float((q[RHO_H].sum() + q[RHO_A].sum()) * dx)


def domain_violation(p: ModelParameters, q: np.ndarray, x: np.ndarray) -> str | None:
    """Describe the first place where ``q`` leaves the physical domain, or None.

    The physical domain is: every conserved variable finite, densities > 0 (the speeds are
    y_i / rho_i + Ve_i), and AO < AO_max = min(AO_max_h, AO_max_a) (at and beyond it an
    equilibrium speed is zero or negative). The message names the variable, its value and
    the position x (m).
    """
    with np.errstate(all="ignore"):
        ao = (p.area_h * q[RHO_H] + p.area_a * q[RHO_A]) / p.road_width
        if (np.isfinite(q).all() and q[RHO_H].min() > 0.0 and q[RHO_A].min() > 0.0
                and ao.max() < p.ao_max):
            return None                                   # fast path, every step
    checks = [(~np.isfinite(q[k]), name, q[k], "not finite") for k, name in enumerate(CONSERVED)]
    checks += [(q[k] <= 0.0, CONSERVED[k], q[k], "density not positive") for k in (RHO_H, RHO_A)]
    checks.append((ao >= p.ao_max, "AO", ao, f"at or above AO_max = {p.ao_max:g}"))
    for bad, name, values, why in checks:
        if np.any(bad):
            i = int(np.argmax(bad))
            return (f"{name} = {float(values[i]):.6g} at x = {float(x[i]):.1f} m "
                    f"(cell {i}): {why}")
    return None
