"""Theory checks of backstepping on the linear plant (paper, section 3, first theorem).

From a sinusoidal stop-and-go perturbation, the linear plant clpsys1-clpsys4 is run

* with the full law control_law until t_f + 20 s (finite-time convergence),
* with only the reflection cancellation -R w+(L) (no kernel) for as long,
* in open loop (U = 0) to 450 s, and further to estimate its growth rate,

and the forward/inverse transforms are checked against each other.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from arzsumo.control.kernels import Kernels, solve_kernels
from arzsumo.control.plant import LinearPlant
from arzsumo.control.transform import BacksteppingLaw, BacksteppingTransform
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
