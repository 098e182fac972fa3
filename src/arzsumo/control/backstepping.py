"""Continuous backstepping boundary control (label control_law) as a :class:`Controller`.

The controller owns a grid of ``n_cells`` cells on [0, L] (the kernel grid). A
:class:`MacroState` on any grid is interpolated linearly onto it; deviations z from the
equilibrium then map to U (veh/s) through one precomputed gain matrix:

    U = U-bar / u_bar_per_u,  U-bar = sum_j G_j . w-bar(x_j) = sum_j (T^T E_j G_j) . z(x_j),

so one evaluation is a dot product of two (4, n_cells+1) arrays. A static state feedback
keeps nothing to wind up: no anti-windup (docs/sumo.md, "Actuation limits").
"""

from __future__ import annotations

import numpy as np

from arzsumo.control.base import Controller, MacroState
from arzsumo.control.kernels import Kernels
from arzsumo.control.transform import BacksteppingLaw
from arzsumo.model.characteristic import Linearization


def interp_extrapolate(x_new: np.ndarray, x: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Linear interpolation of f(x) at x_new, extrapolated linearly beyond the end points.

    Cell-centred fields (detectors, finite volumes) do not reach x = 0 and x = L, where
    the law's boundary term -R w+(L) is evaluated: constant extrapolation would bias it.
    """
    out = np.interp(x_new, x, f)
    if x.size >= 2:
        lo, hi = x_new < x[0], x_new > x[-1]
        out[lo] = f[0] + (x_new[lo] - x[0]) * (f[1] - f[0]) / (x[1] - x[0])
        out[hi] = f[-1] + (x_new[hi] - x[-1]) * (f[-1] - f[-2]) / (x[-1] - x[-2])
    return out


class StateMap:
    """Maps a nonlinear :class:`MacroState` to deviations z and Riemann variables on a grid."""

    def __init__(self, lin: Linearization, x: np.ndarray) -> None:
        eq = lin.equilibrium
        self.lin = lin
        self.x = x
        self.reference = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[:, None]
        self.scaling = lin.system.scaling(x).T                    # (4, N+1)
        self._source: np.ndarray | None = None
        self._matrix = np.empty((0, x.size))

    def deviations(self, state: MacroState) -> np.ndarray:
        """z = (rho_h~, v_h~, rho_a~, v_a~) on the grid, shape (4, N+1)."""
        fields = np.vstack((state.rho_h, state.v_h, state.rho_a, state.v_a))
        if state.x.shape == self.x.shape and np.array_equal(state.x, self.x):
            return fields - self.reference
        return fields @ self._interpolation(state.x) - self.reference

    def _interpolation(self, x_source: np.ndarray) -> np.ndarray:
        """Matrix W with f(self.x) = f(x_source) @ W, cached for the last source grid."""
        if self._source is None or not np.array_equal(self._source, x_source):
            eye = np.eye(x_source.size)
            self._matrix = np.stack([interp_extrapolate(self.x, x_source, row) for row in eye])
            self._source = np.array(x_source, copy=True)
        return self._matrix

    def riemann(self, z: np.ndarray) -> np.ndarray:
        """Scaled Riemann variables w-bar = E(x) T z."""
        return self.scaling * (self.lin.T @ z)


class Backstepping(Controller):
    """Continuous backstepping: U(t) from control_law at every check.

    ``lin`` linearises at a congested equilibrium; ``kernels`` are solved for ``lin.system``
    (:func:`arzsumo.control.kernels.solve_kernels`, or cached by
    :func:`arzsumo.kernel_cache.cached_kernels`).
    """

    name = "backstepping"

    def __init__(self, lin: Linearization, kernels: Kernels) -> None:
        super().__init__()
        self.lin = lin
        self.law = BacksteppingLaw(lin.system, kernels)
        self.state_map = StateMap(lin, kernels.x)
        # gains on z: U = sum(gain_z * z)
        self.gain_z = np.einsum("aj,ab->bj", self.law.gain * self.state_map.scaling, lin.T) \
            / lin.u_bar_per_u

    def u_of_z(self, z: np.ndarray) -> float:
        """U (veh/s) from deviations on the kernel grid, shape (4, n_cells+1)."""
        return float(np.sum(self.gain_z * z))

    def check_riemann(self, t: float, w_bar: np.ndarray) -> float:
        """Check on a scaled Riemann state at the kernel nodes; returns U-bar (updated)."""
        u_bar = self.law.u_bar(w_bar)
        u = u_bar / self.lin.u_bar_per_u
        self.log.record(t, u, u, True)
        return u_bar

    def decide(self, state: MacroState) -> float:
        u = self.u_of_z(self.state_map.deviations(state))
        self.log.record(state.t, u, u, True)
        return u
