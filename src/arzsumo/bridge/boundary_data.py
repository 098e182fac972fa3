"""What the PDE twins take from SUMO: the measured state, and the smoothed boundary data.

One pure function per quantity, shared by the twins beside SUMO (one period at a time,
:class:`~arzsumo.bridge.twins.TwinPair`) and the identification (a whole run,
:func:`~arzsumo.bridge.replay_data.replay_data_of`), so both feed the twin the same numbers,
bit for bit.
"""

from __future__ import annotations

import math

import numpy as np

from arzsumo.bridge.estimator import fill_speeds
from arzsumo.model.params import ModelParameters

#: smallest density handed to a twin, veh/m (it divides by densities)
RHO_FLOOR = 1e-4


def measured_state(params: ModelParameters, rho_h: np.ndarray, v_h: np.ndarray,
                   rho_a: np.ndarray, v_a: np.ndarray) -> np.ndarray:
    """Edie cells as a complete primitive state (4, n): (rho_h, v_h, rho_a, v_a), SI; empty
    cells' speeds (NaN) at Ve of the raw densities (paper eq. ``Ve``), then the densities
    floored at :data:`RHO_FLOOR`."""
    v_h, v_a = fill_speeds(params, np.asarray(rho_h, float), np.asarray(v_h, float),
                           np.asarray(rho_a, float), np.asarray(v_a, float))
    return np.vstack([np.maximum(rho_h, RHO_FLOOR), v_h, np.maximum(rho_a, RHO_FLOOR), v_a])


def smooth_step(previous: np.ndarray | float, new: np.ndarray | float, dt: float,
                tau: float) -> np.ndarray | float:
    """One step of exponential smoothing: previous + (1 - exp(-dt / tau)) (new - previous).

    ``dt``, ``tau``: step and time constant, s. It keeps the mean of a constant signal
    (and so the vehicle count of a smoothed flow).
    """
    return previous + (1.0 - math.exp(-dt / tau)) * (new - previous)


def inlet_series(params: ModelParameters, start: np.ndarray, first_cells: np.ndarray,
                 dt: float, tau: float) -> np.ndarray:
    """The inlet state (T, 4) the twins hold at x = 0 during each control period.

    The smoothing starts at ``start``, SUMO's first cell (4,) at the start of control (NaN
    speed where empty; ``params``' Ve fills it), without history; period k smooths in
    ``first_cells[k]``, the first cell measured over it (the twin of period k advances
    after SUMO's period k is measured). ``dt``, ``tau``: control period and time constant, s.
    """
    state = measured_state(params, *np.asarray(start, float)[:, None])[:, 0]
    cells = np.asarray(first_cells, float)
    out = np.empty((cells.shape[0], 4))
    for k in range(cells.shape[0]):
        state = smooth_step(state, measured_state(params, *cells[k][:, None])[:, 0], dt, tau)
        out[k] = state
    return out


def outflow_series(q0: float, outflow: np.ndarray, dt: float, tau: float) -> np.ndarray:
    """The smoothed total outflow (T,) at x = L during each period, veh/s, from ``q0`` (the
    nominal meter's outflow) and SUMO's ``outflow[k]`` over period k; ``dt``, ``tau`` as
    :func:`inlet_series`."""
    q, out = float(q0), np.empty(len(outflow))
    for k, value in enumerate(np.asarray(outflow, float)):
        q = smooth_step(q, float(value), dt, tau)
        out[k] = q
    return out
