r"""Anti-collocated boundary observer and observer-based ETC (section 4, ob-sys1 to dtof).

Observer. With the measurement y(t) = w-(0, t) (physically: the class speeds at the inlet,
since rho~(0) = 0 there), the observer is ob-sys1/ob-sys2 with output injection
P+(x) (y - w-hat(0)), P-(x) (y - w-hat(0)) and, as in Di Meglio, Vazquez and Krstic (2013)
and Hu et al. (2015), the measured value in its inlet condition: w+hat(0) = Q y(t). (With
ob-sys1-bd's Q w-hat(0) the error keeps the reflection loop and loses finite-time
convergence.) The error (u, v) = w - w-hat then satisfies u(0) = 0 and

    u_t + Lambda+ u_x = Sigma++ u + Sigma+- v - P+(x) v(0),
    v_t - mu v_x      = Sigma-+ u - P-(x) v(0),      v(L) = R u(L).

Observer kernels. (u, v) = (a, b) - int_0^x (F(x, xi), G(x, xi)) b(xi) dxi maps it to a
target system with a(0) = 0, b(L) = R a(L) and no b-terms in the a equation, which
vanishes after t_f = L/min(lambda_i) + L/mu, if (derivation as for back4)

    Lambda+ F_x - mu F_xi = Sigma++(x) F + Sigma+-(x) G,   F(x, x) = -(Lambda+ + mu)^-1 Sigma+-(x)
    G_x + G_xi = -Sigma-+(x) F / mu,                        G(L, xi) = R F(L, xi),

and P+(x) = -mu F(x, 0), P-(x) = -mu G(x, 0). The reflection (x, xi) -> (L - xi, L - x)
turns this into the controller kernel equations of a *dual* system with
Sigma~(xi) = Sigma(L - xi)^T and Q~_i = mu R_i / lambda_i, so the same tested solver gives
F, G. For the mixed ARZ model Sigma+- = 0, hence F = G = 0 and P = 0: the observer
converges in finite time by the inlet condition alone.

Observer-based ETC. The law bs_control_of and its sampled version bs_control_of_etc are
control_law and the mechanism of defdynamic applied to the estimate (discrepancy dtof).

Anti-windup (:meth:`ObserverEtc.applied`): ob-sys2-bd integrates the next interval with
the U-bar applied (without it, the held command); the trigger projects dtof on the
actuator's range as the full-state ETC does.
"""

from __future__ import annotations

import math

import numpy as np

from arzsumo.control.base import MacroState
from arzsumo.control.etc import PAPER_DESIGN, EtcDesign, TriggeredLaw, u_bar_range
from arzsumo.control.kernels import Kernels, solve_kernels
from arzsumo.control.plant import LinearPlant, step_dividing
from arzsumo.model.characteristic import CharacteristicSystem, Linearization


def dual_system(system: CharacteristicSystem) -> CharacteristicSystem:
    """The system whose controller kernels are the reflected observer kernels."""
    rate = np.diag(system.j_hat) / system.lam
    length = system.length
    j_dual = system.j_hat.T * np.exp((rate[:, None] - rate[None, :]) * length)
    np.fill_diagonal(j_dual, np.diag(system.j_hat))
    q_dual = system.lam_minus * system.R / system.lam_plus
    return CharacteristicSystem(system.lam, j_dual, q_dual, system.R, length)


def observer_gains(system: CharacteristicSystem, n_cells: int) -> np.ndarray:
    """P(x) = (P+(x), P-(x)) on x_j = j L / n_cells, shape (n+1, n_cells+1), 1/s."""
    dual = solve_kernels(dual_system(system), n_cells)
    mu = system.lam_minus
    # P+ = -mu F(x_j, 0) with F(x_j, 0) = K~(L, L - x_j); P- likewise with G = M~
    return np.vstack([-mu * dual.K[:, -1, ::-1], -mu * dual.M[-1, ::-1]])


class BoundaryObserver:
    """The observer PDE on the kernel grid, advanced between checks.

    The measurement is linearly interpolated between checks; the applied U-bar is the one
    held over the interval.
    """

    def __init__(self, system: CharacteristicSystem, n_cells: int) -> None:
        self.system = system
        self.n_cells = n_cells
        self.gains = observer_gains(system, n_cells)
        self._plants: dict[float, LinearPlant] = {}
        self._dt_max = LinearPlant(system, n_cells).dt
        self.reset()

    def reset(self) -> None:
        """Start from zero: nothing known."""
        self.estimate = np.zeros((self.system.n + 1, self.n_cells + 1))
        self.t: float | None = None
        self.y_last = 0.0

    def _plant(self, dt: float) -> LinearPlant:
        key = round(dt, 12)
        if key not in self._plants:
            self._plants[key] = LinearPlant(self.system, self.n_cells, dt=dt)
        return self._plants[key]

    def advance(self, t: float, y: float, u_bar: float) -> np.ndarray:
        """Advance the estimate to time t (s) given y(t) and the U-bar held meanwhile."""
        if self.t is None:
            self.t, self.y_last = t, y
            self.estimate[: self.system.n, 0] = self.system.Q * y
            return self.estimate
        span = t - self.t
        if span > 0:
            dt = step_dividing(span, self._dt_max)
            plant = self._plant(dt)
            plant.state, plant.t, plant.u_bar_applied = self.estimate, 0.0, u_bar
            steps = round(span / dt)
            for k in range(1, steps + 1):
                y_k = self.y_last + (y - self.y_last) * k / steps
                innovation = y_k - plant.state[-1, 0]
                plant.step(lambda _t, _w: u_bar, inlet=y_k, injection=self.gains * innovation)
            self.estimate = plant.state
        self.t, self.y_last = t, y
        return self.estimate


class ObserverEtc(TriggeredLaw):
    """Observer-based dynamic ETC: measurement only at the inlet (bs_control_of_etc)."""

    name = "observer-etc"

    def __init__(self, lin: Linearization, kernels: Kernels,
                 design: EtcDesign = PAPER_DESIGN) -> None:
        super().__init__(lin, kernels, design)
        self.observer = BoundaryObserver(lin.system, kernels.n_cells)
        #: U-bar the observer integrates over the next interval: the applied one
        self.u_bar_input = 0.0
        eq = lin.equilibrium
        self._y_weights = lin.T[3, [1, 3]]            # y = w_4(0) with rho~(0) = 0
        self._v_ref = np.array([eq.v_h, eq.v_a])

    def reset(self) -> None:
        super().reset()
        self.observer.reset()
        self.u_bar_input = 0.0

    def measurement_of(self, state: MacroState) -> float:
        """y = w-(0) from the class speeds in the first cell (inlet densities at rho*)."""
        dv = np.array([state.v_h[0], state.v_a[0]]) - self._v_ref
        return float(self._y_weights @ dv)

    def check_measurement(self, t: float, y: float) -> float:
        """Advance the observer to t with y(t), run the mechanism on the estimate; U-bar."""
        estimate = self.observer.advance(t, y, self.u_bar_input)
        r = self.trigger.check(t, estimate)
        self.u_bar_input = r.u_bar_held
        return self._record(t, r, y=y)

    def applied(self, u: float, lower: float = -math.inf, upper: float = math.inf) -> None:
        """Anti-windup: the observer integrates with the applied ``u`` (veh/s) until the
        next check; the trigger compares what is deliverable in ``[lower, upper]``."""
        per = self.lin.u_bar_per_u
        self.u_bar_input = u * per
        self.trigger.bounds = u_bar_range(lower, upper, per)

    def decide(self, state: MacroState) -> float:
        return self.check_measurement(state.t, self.measurement_of(state)) / self.lin.u_bar_per_u
