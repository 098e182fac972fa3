"""Theory checks of backstepping on the linear plant (paper, section 3, first theorem).

From a sinusoidal stop-and-go perturbation, the linear plant clpsys1-clpsys4 is run

* with the full law control_law until t_f + 20 s (finite-time convergence),
* with only the reflection cancellation -R w+(L) (no kernel) for as long,
* in open loop (U = 0) to 450 s, and further to estimate its growth rate,

and the forward/inverse transforms are checked against each other.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import Controller
from arzsumo.control.etc import PAPER_DESIGN, EventTriggered, Lyapunov
from arzsumo.control.events import event_summary, lyapunov_convergence_time
from arzsumo.control.kernels import Kernels, solve_kernels
from arzsumo.control.observer import ObserverEtc
from arzsumo.control.plant import LinearPlant, step_dividing
from arzsumo.control.transform import BacksteppingLaw, BacksteppingTransform
from arzsumo.errors import ModelError
from arzsumo.model.characteristic import Linearization


def sinusoidal_deviation(lin: Linearization, x: np.ndarray, amplitude: float = 0.1,
                         waves: int = 1) -> np.ndarray:
    """Stop-and-go z(x, 0): densities up by ``amplitude`` of rho*, speeds down, sin(2 pi k x / L).

    Vanishes at both ends, so it satisfies the boundary conditions at t = 0.
    """
    eq = lin.equilibrium
    s = np.sin(2 * np.pi * waves * x / eq.params.length)
    return amplitude * np.vstack([eq.rho_h * s, -eq.v_h * s, eq.rho_a * s, -eq.v_a * s])


def z_norm(lin: Linearization, w_bar: np.ndarray, x: np.ndarray) -> float:
    """L2 norm over [0, L] of z = T^-1 E^-1 w-bar (mixed units, used only in ratios)."""
    z = lin.from_riemann(w_bar, x)
    return float(np.sqrt(np.trapezoid(np.sum(z**2, axis=0), x)))


@dataclass(frozen=True)
class VerifyReport:
    """Results of :func:`verify_backstepping` (times in s, ratios dimensionless)."""

    t_f: float
    closed_loop_ratio: float
    no_kernel_ratio: float
    open_loop_ratio: float
    open_loop_growth_rate: float
    open_loop_min_ratio: float
    inverse_error: float
    law_forms_error: float
    grid: int

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def _run(lin: Linearization, n_cells: int, w0: np.ndarray, t_end: float, u_bar_fn,
         sample_every: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    plant = LinearPlant(lin.system, n_cells)
    plant.reset(w0)
    times, norms = [0.0], [z_norm(lin, w0, plant.x)]
    next_t = sample_every
    while plant.t < t_end - 1e-9:
        plant.step(u_bar_fn)
        if plant.t >= next_t - 1e-9:
            times.append(plant.t)
            norms.append(z_norm(lin, plant.state, plant.x))
            next_t += sample_every
    return np.array(times), np.array(norms)


def verify_backstepping(lin: Linearization, n_cells: int = 200,
                        kernels: Kernels | None = None, open_loop_horizon: float = 450.0,
                        growth_horizon: float = 1500.0) -> VerifyReport:
    """Run the theory checks; see the module docstring."""
    system = lin.system
    kernels = kernels or solve_kernels(system, n_cells)
    law = BacksteppingLaw(system, kernels)
    x = kernels.x
    w0 = lin.to_riemann(sinusoidal_deviation(lin, x), x)
    t_end = system.t_f + 20.0
    _, cl = _run(lin, n_cells, w0, t_end, lambda t, w: law.u_bar(w))
    _, nk = _run(lin, n_cells, w0, t_end, lambda t, w: law.u_bar_no_kernel(w))
    times, ol = _run(lin, n_cells, w0, growth_horizon, lambda t, w: 0.0, sample_every=5.0)
    at_horizon = ol[np.searchsorted(times, open_loop_horizon - 1e-9)]
    tail = times >= growth_horizon / 2
    growth = float(np.polyfit(times[tail], np.log(ol[tail]), 1)[0])
    # inverse check: forward with these kernels, inverse with an independent solve on a
    # twice finer grid sampled at our nodes, so the error measures the kernels, not algebra
    fine = solve_kernels(system, 2 * n_cells)
    sub = np.s_[..., ::2, ::2]
    pair = Kernels(x, kernels.K, kernels.M, fine.L[sub], fine.N[sub])
    alpha, beta = BacksteppingTransform(kernels).forward(w0)
    back = BacksteppingTransform(pair).inverse(alpha, beta)
    inverse_error = float(np.linalg.norm(back - w0) / np.linalg.norm(w0))
    forms = abs(law.u_bar(w0) - law.u_bar_from_target(alpha, beta)) / abs(law.u_bar(w0))
    return VerifyReport(
        t_f=system.t_f, closed_loop_ratio=float(cl[-1] / cl[0]),
        no_kernel_ratio=float(nk[-1] / nk[0]), open_loop_ratio=float(at_horizon / ol[0]),
        open_loop_growth_rate=growth, open_loop_min_ratio=float(ol.min() / ol[0]),
        inverse_error=inverse_error, law_forms_error=float(forms), grid=n_cells)


@dataclass(frozen=True)
class ClosedLoopRun:
    """A controller on the linear plant: the controller's log and per-check series.

    ``V`` is the Lyapunov functional (label lyapunov) of the *true* state at each check,
    ``norm`` its L2 norm of z, ``estimation_error`` the relative L2 error of the
    observer's estimate (NaN for full-state controllers).
    """

    controller: str
    period: float
    horizon: float
    t: np.ndarray
    V: np.ndarray
    norm: np.ndarray
    estimation_error: np.ndarray
    log: object

    def summary(self) -> dict[str, float | int | str]:
        ev = event_summary(self.log, self.horizon)
        m = np.asarray(self.log.extra.get("m", [np.nan]))
        m_stats = (float(m.min()), float(m.max())) if np.isfinite(m).all() else (np.nan, np.nan)
        return {
            "controller": self.controller, "period": self.period, "horizon": self.horizon,
            "triggers": ev.triggers, "release_time": ev.release_time,
            "min_interval": ev.min_interval, "mean_interval": ev.mean_interval,
            "V_ratio": float(self.V[-1] / self.V[0]),
            "final_norm_ratio": float(self.norm[-1] / self.norm[0]),
            "lyapunov_convergence_time": lyapunov_convergence_time(self.t, self.V),
            "m_min": m_stats[0], "m_max": m_stats[1],
            "m_nonnegative_checks": int(np.sum(np.asarray(m) >= 0)),
        }


def _controller_check(lin: Linearization, kernels: Kernels, controller: str,
                      design) -> tuple[Controller, Callable[[float, np.ndarray], float]]:
    """The controller named ``controller`` and its check(t, w) -> U-bar on the Riemann state.

    The observer-based ETC sees only the measured w-(0), the others the full state.
    """
    if controller == "backstepping":
        ctrl: Controller = Backstepping(lin, kernels)
        return ctrl, ctrl.check_riemann
    if controller == "etc":
        ctrl = EventTriggered(lin, kernels, design)
        return ctrl, ctrl.check_riemann
    if controller == "observer-etc":
        obs = ObserverEtc(lin, kernels, design)
        return obs, lambda t, w: obs.check_measurement(t, float(w[-1, 0]))
    raise ModelError(f"controller = {controller!r} is not allowed: 'backstepping', 'etc' "
                     "or 'observer-etc'")


class _CheckSeries:
    """Series recorded at each check from the *true* state: t (s), V (label lyapunov), the
    L2 norm of z, and the observer's relative estimation error (NaN without observer)."""

    def __init__(self, lin: Linearization, kernels: Kernels, design, w0: np.ndarray,
                 observer_etc: ObserverEtc | None) -> None:
        self.lin, self.x, self.w0, self.observer_etc = lin, kernels.x, w0, observer_etc
        self.transform = BacksteppingTransform(kernels)
        self.lyap = Lyapunov(lin.system, kernels.x, design)
        self.t: list[float] = []
        self.V: list[float] = []
        self.norm: list[float] = []
        self.error: list[float] = []

    def __call__(self, t: float, w: np.ndarray) -> None:
        self.t.append(t)
        self.V.append(self.lyap(*self.transform.forward(w)))
        self.norm.append(z_norm(self.lin, w, self.x))
        self.error.append(np.nan if self.observer_etc is None else
                          np.linalg.norm(w - self.observer_etc.observer.estimate)
                          / np.linalg.norm(self.w0))

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return np.array(self.t), np.array(self.V), np.array(self.norm), np.array(self.error)


def _run_held(plant: LinearPlant, check: Callable[[float, np.ndarray], float],
              observe: _CheckSeries, w0: np.ndarray, period: float, horizon: float) -> None:
    """Step ``plant`` from ``w0`` to ``horizon`` s, checking every ``period`` s (at 0, Delta,
    ..., T - Delta) and holding the check's output in between; observe at every check."""
    dt = plant.dt
    held = check(0.0, w0)
    observe(0.0, w0)
    plant.u_bar_applied = held
    steps_per_check = round(period / dt)
    count = 0

    def u_bar_fn(t: float, w: np.ndarray) -> float:
        nonlocal held, count
        count += 1
        if count % steps_per_check == 0:
            if t < horizon - 0.5 * dt:
                held = check(t, w)
            observe(t, w)
        return held

    while plant.t < horizon - 0.5 * dt:
        plant.step(u_bar_fn)


def run_closed_loop(lin: Linearization, kernels: Kernels, controller: str = "etc",
                    period: float = 1.0, horizon: float = 450.0, design=None,
                    amplitude: float = 0.1) -> ClosedLoopRun:
    """Run ``controller`` ("backstepping", "etc", "observer-etc") on the linear plant.

    The controller is checked every ``period`` s (the plant step divides it) and its
    output held in between; the plant starts from the sinusoidal stop-and-go deviation.
    """
    design = design or PAPER_DESIGN
    system, n = lin.system, kernels.n_cells
    dt = step_dividing(period, LinearPlant(system, n).dt)
    plant = LinearPlant(system, n, dt=dt)
    w0 = lin.to_riemann(sinusoidal_deviation(lin, kernels.x, amplitude), kernels.x)
    plant.reset(w0)
    ctrl, check = _controller_check(lin, kernels, controller, design)
    series = _CheckSeries(lin, kernels, design, w0,
                          ctrl if isinstance(ctrl, ObserverEtc) else None)
    _run_held(plant, check, series, w0, period, horizon)
    return ClosedLoopRun(controller, period, horizon, *series.arrays(), ctrl.log)

