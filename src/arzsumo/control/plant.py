"""Linear plant clpsys1-clpsys4 in scaled Riemann variables, for verifying controllers.

Scheme: Strang splitting of transport and in-domain coupling.

* Transport: semi-Lagrangian, upwind-biased cubic interpolation (the four nodes around the
  foot x_j - lambda_i dt), exact for the fastest wave at Courant number 1. Third-order in
  space for smooth data, stable for Courant numbers in (0, 1]. ``scheme="upwind"`` gives
  the first-order donor-cell scheme instead (linear interpolation).
* Coupling Sigma(x) w-bar: the exact propagator exp(Sigma(x_j) dt / 2) at every node
  (4th-order Taylor series; ||Sigma dt|| is below 1e-2 here).
* Boundaries after each step: w+(0) = Q w-(0) (clpsys3) and
  w-(L) = R w+(L) + U-bar (clpsys4), with U-bar from the controller evaluated on the
  updated state (so a continuous law sets beta(L) = 0 at every step).

The time step is CFL-bounded: dt <= cfl h / max |lambda|.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from arzsumo.control.kernels import lagrange_stencil
from arzsumo.errors import ModelError, require
from arzsumo.model.characteristic import CharacteristicSystem

#: maps (t, state) -> U-bar to apply on the outlet at time t
UBarFunction = Callable[[float, np.ndarray], float]


class LinearPlant:
    """The n+1 linear hyperbolic plant on nodes x_j = j L / n_cells.

    ``cfl`` is the Courant number of the fastest wave, in (0, 1]; ``scheme`` "cubic" or
    "upwind" (module docstring); ``dt`` the time step (s), at most (default) the CFL step.
    """

    def __init__(self, system: CharacteristicSystem, n_cells: int, cfl: float = 1.0,
                 scheme: str = "cubic", dt: float | None = None) -> None:
        require(0 < cfl <= 1, "cfl", cfl, "a Courant number in (0, 1]", ModelError)
        require(scheme in ("cubic", "upwind"), "scheme", scheme, "'cubic' or 'upwind'",
                ModelError)
        self.system = system
        self.x = np.linspace(0.0, system.length, n_cells + 1)
        h = self.x[1] - self.x[0]
        dt_max = cfl * h / float(np.abs(system.lam).max())
        require(dt is None or 0 < dt <= dt_max * (1 + 1e-12), "dt", dt,
                f"a time step in (0, {dt_max:.4g}] s (CFL)", ModelError)
        self.dt = dt_max if dt is None else float(dt)
        order = 4 if scheme == "cubic" else 2
        feet = np.clip(self.x[None, :] - system.lam[:, None] * self.dt, 0.0, system.length)
        stencils = [lagrange_stencil(self.x, f, order) for f in feet]
        self._idx = np.stack([s[0] for s in stencils])        # (n+1, N+1, order)
        self._w = np.stack([s[1] for s in stencils])
        a = system.sigma(self.x) * (0.5 * self.dt)            # (N+1, n+1, n+1)
        term = np.broadcast_to(np.eye(system.n + 1), a.shape).copy()
        prop = term.copy()
        for k in range(1, 5):
            term = term @ a / k
            prop = prop + term
        self._half_source = prop
        self.t = 0.0
        self.state = np.zeros((system.n + 1, n_cells + 1))
        self.u_bar_applied = 0.0

    def reset(self, w_bar0: np.ndarray) -> None:
        """Start again at t = 0 from w-bar0, shape (n+1, n_cells+1)."""
        w_bar0 = np.asarray(w_bar0, float)
        if w_bar0.shape != self.state.shape:
            raise ModelError(f"initial state shape {w_bar0.shape} is not allowed: expected "
                             f"{self.state.shape}")
        self.state = w_bar0.copy()
        self.t = 0.0
        self.u_bar_applied = 0.0

    def step(self, u_bar_fn: UBarFunction, inlet: float | None = None,
             injection: np.ndarray | None = None) -> None:
        """Advance one time step; the outlet boundary uses ``u_bar_fn(t + dt, state)``.

        For an observer copy of the plant: ``inlet`` replaces w-(0) in the inlet condition
        w+(0) = Q w-(0) (the measurement y), and ``injection`` (n+1, N+1) is added times
        dt as an output-injection source.
        """
        n = self.system.n
        w = np.einsum("jab,bj->aj", self._half_source, self.state)
        rows = np.arange(n + 1)[:, None, None]
        w = np.sum(self._w * w[rows, self._idx], axis=-1)
        w = np.einsum("jab,bj->aj", self._half_source, w)
        if injection is not None:
            w += self.dt * injection
        self.t += self.dt
        w[:n, 0] = self.system.Q * (w[n, 0] if inlet is None else inlet)
        w[n, -1] = self.system.R @ w[:n, -1] + self.u_bar_applied
        self.u_bar_applied = u_bar_fn(self.t, w)
        w[n, -1] = self.system.R @ w[:n, -1] + self.u_bar_applied
        self.state = w


def step_dividing(period: float, dt_max: float) -> float:
    """The largest time step <= dt_max that divides ``period`` (s) into whole steps."""
    return period / math.ceil(period / dt_max - 1e-9)
