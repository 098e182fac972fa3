"""First order plus dead time (FOPDT) fitted to step responses.

The actuator map from the ramp meter's green share u to the section's mainline outflow
y = q(L, t) (veh/s) is modelled, around an operating point, as

    y(t) = y0 + K du (1 - exp(-(t - t0 - theta) / T))   for t > t0 + theta,
    y(t) = y0                                           otherwise,

for a step of size du in u at time t0: static gain K (veh/s per unit green share; < 0 on
the ramp network, more ramp green takes merge capacity), dead time theta (s) and time
constant T (s). One or more steps are fitted together: K, theta and T are shared, each
step has its own level y0 (the traffic before it). Measured flows are counts over bins of
width w (vehicles crossing x = L in (t - w, t]), so the model is averaged over the same
bins (:func:`fopdt_response` with ``bin_width``); otherwise a 1 s bin biases theta by
about w / 2.

The fit is :func:`scipy.optimize.least_squares` (trust region reflective, bounds theta
>= 0, T > 0) from a small grid of starts in (theta, T), the best kept: the residual is
only piecewise smooth in theta (kinks where t0 + theta crosses a sample). 1-sigma from the
Jacobian at the optimum, covariance s^2 (J^T J)^-1 with s^2 the residual variance.

Pure math: numpy and scipy only.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from arzsumo.errors import ArzsumoError, require


@dataclass(frozen=True)
class StepData:
    """One record: samples ``y`` (veh/s) at ``t`` (s, end of each bin) around one or more
    steps of the input, ``du[j]`` at ``t0[j]`` (s), on one level y0.

    Samples before the first step fix the level y0; a staircase of steps in one record
    shares it (its later levels follow from K), a single step per record leaves each
    step its own level.
    """

    t: np.ndarray
    y: np.ndarray
    t0: tuple[float, ...]
    du: tuple[float, ...]

    def __post_init__(self) -> None:
        t, y = np.asarray(self.t, float), np.asarray(self.y, float)
        t0 = tuple(float(v) for v in np.atleast_1d(self.t0))
        du = tuple(float(v) for v in np.atleast_1d(self.du))
        require(t.ndim == 1 and t.size >= 4 and t.shape == y.shape, "t", t.shape,
                "a 1-D array of at least 4 times, as many as y", ArzsumoError)
        require(bool(np.all(np.isfinite(t)) and np.all(np.isfinite(y))), "y", "non-finite",
                "finite times and flows", ArzsumoError)
        require(len(du) == len(t0) >= 1 and all(math.isfinite(v) and v != 0 for v in du),
                "du", du, "finite, non-zero steps, one per step time t0", ArzsumoError)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "t0", t0)
        object.__setattr__(self, "du", du)


@dataclass(frozen=True)
class FopdtFit:
    """A fitted FOPDT model and its 1-sigma uncertainties (Jacobian at the optimum).

    Attributes
    ----------
    gain, delay, time_constant : float
        K (veh/s per unit green share), theta (s), T (s).
    y0 : tuple of float
        Level before each step, veh/s.
    residual_sd : float
        Residual standard deviation, veh/s (degrees of freedom: samples - parameters).
    sigma_gain, sigma_delay, sigma_time_constant : float
        1-sigma of K (veh/s), theta (s), T (s).
    sigma_y0 : tuple of float
        1-sigma of each y0, veh/s.
    n_samples : int
        Samples fitted.
    """

    gain: float
    delay: float
    time_constant: float
    y0: tuple[float, ...]
    residual_sd: float
    sigma_gain: float
    sigma_delay: float
    sigma_time_constant: float
    sigma_y0: tuple[float, ...]
    n_samples: int


def _integral(s: np.ndarray, tau: float) -> np.ndarray:
    """Integral from 0 to s of the unit response 1 - exp(-s / T) (0 for s < 0), s."""
    sp = np.maximum(s, 0.0)
    return sp - tau * -np.expm1(-sp / tau)


def fopdt_response(t: np.ndarray, y0: float, gain: float, du: float, t0: float,
                   delay: float, time_constant: float, bin_width: float = 0.0
                   ) -> np.ndarray:
    """FOPDT step response at ``t`` (s): point values, or bin means over (t - w, t].

    Parameters
    ----------
    t : ndarray
        Times, s (bin ends when ``bin_width`` > 0).
    y0, gain, du : float
        Level (veh/s), K (veh/s per unit input) and step size (input units).
    t0, delay, time_constant : float
        Step time, dead time theta and time constant T, s (T > 0).
    bin_width : float
        w, s; 0 gives point values.
    """
    s = np.asarray(t, float) - t0 - delay
    if bin_width > 0:
        unit = (_integral(s, time_constant) - _integral(s - bin_width, time_constant)) \
            / bin_width
    else:
        unit = -np.expm1(-np.maximum(s, 0.0) / time_constant)
    return y0 + gain * du * unit


def _unit_and_derivatives(s: np.ndarray, tau: float, w: float
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit response r at s = t - t0 - theta (bin mean over (s - w, s] when w > 0) and its
    derivatives with respect to theta and T."""
    def point(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        xp = np.maximum(x, 0.0)
        e = np.exp(-xp / tau)
        return 1.0 - e, np.where(x > 0, e / tau, 0.0), -xp / tau**2 * e

    if w <= 0:
        r, dr_ds, dr_dtau = point(s)
        return r, -dr_ds, dr_dtau

    def integral(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        xp = np.maximum(x, 0.0)
        e = np.exp(-xp / tau)
        return xp - tau * (1.0 - e), 1.0 - e, -(1.0 - e) + xp / tau * e

    i1, d1, g1 = integral(s)
    i0, d0, g0 = integral(s - w)
    return (i1 - i0) / w, -(d1 - d0) / w, (g1 - g0) / w


def _model(p: np.ndarray, steps: Sequence[StepData], w: float
           ) -> tuple[np.ndarray, np.ndarray]:
    """Stacked model values and their Jacobian in p = (K, theta, T, y0_1, ..., y0_n)."""
    gain, delay, tau = p[:3]
    vals, rows = [], []
    for i, st in enumerate(steps):
        jac = np.zeros((st.t.size, p.size))
        sum_r = np.zeros(st.t.size)
        for t0, du in zip(st.t0, st.du, strict=True):
            r, dr_dtheta, dr_dtau = _unit_and_derivatives(st.t - t0 - delay, tau, w)
            sum_r += du * r
            jac[:, 1] += gain * du * dr_dtheta
            jac[:, 2] += gain * du * dr_dtau
        jac[:, 0] = sum_r
        jac[:, 3 + i] = 1.0
        vals.append(p[3 + i] + gain * sum_r)
        rows.append(jac)
    return np.concatenate(vals), np.vstack(rows)


def _residual(p: np.ndarray, steps: Sequence[StepData], w: float) -> np.ndarray:
    return _model(p, steps, w)[0] - np.concatenate([st.y for st in steps])


def _jacobian(p: np.ndarray, steps: Sequence[StepData], w: float) -> np.ndarray:
    return _model(p, steps, w)[1]


def _initial_level_and_gain(steps: Sequence[StepData], delay: float = 5.0,
                            tau: float = 10.0) -> tuple[np.ndarray, float]:
    """y0 per record and K: linear least squares with theta and T held at a guess."""
    p = np.r_[1.0, delay, tau, np.zeros(len(steps))]
    jac = _jacobian(p, steps, 0.0)
    design = np.delete(jac, [1, 2], axis=1)          # columns K, y0_1..y0_n
    coef = np.linalg.lstsq(design, np.concatenate([st.y for st in steps]), rcond=None)[0]
    return coef[1:], float(coef[0])


def fit_fopdt(steps: Sequence[StepData], bin_width: float = 1.0,
              delay_starts: Sequence[float] = (0.0, 5.0, 15.0),
              tau_starts: Sequence[float] = (2.0, 10.0, 40.0),
              max_delay: float = 60.0, max_tau: float = 300.0) -> FopdtFit:
    """Fit y = y0_i + K sum_j du_ij (1 - exp(-(t - t0_ij - theta) / T)) to records i.

    Parameters
    ----------
    steps : sequence of StepData
        The records; K, theta and T are shared, y0 is one per record.
    bin_width : float
        Width w of the bins the samples average over, s (0: point samples).
    delay_starts, tau_starts : sequence of float
        Grid of starting values for theta and T, s; the best optimum is kept.
    max_delay, max_tau : float
        Upper bounds of theta and T, s.

    Returns
    -------
    FopdtFit
        Estimates, residual sd and Jacobian 1-sigmas (infinite when singular).
    """
    require(len(steps) >= 1, "steps", len(steps), "at least one step", ArzsumoError)
    y0, k0 = _initial_level_and_gain(steps)
    n = len(steps)
    lo = np.r_[-np.inf, 0.0, 1e-3, np.full(n, -np.inf)]
    hi = np.r_[np.inf, max_delay, max_tau, np.full(n, np.inf)]
    best = None
    for d0, tau0 in itertools.product(delay_starts, tau_starts):
        x0 = np.r_[k0, min(d0, max_delay), min(tau0, max_tau), y0]
        sol = least_squares(_residual, x0, jac=_jacobian, bounds=(lo, hi),
                            args=(steps, bin_width), x_scale="jac")
        if best is None or sol.cost < best.cost:
            best = sol
    return _with_uncertainty(best, n)


def _with_uncertainty(sol: object, n_steps: int) -> FopdtFit:
    """FopdtFit from a least_squares result: s^2 (J^T J)^-1 at the optimum."""
    res, jac, p = sol.fun, sol.jac, sol.x  # type: ignore[attr-defined]
    dof = max(res.size - p.size, 1)
    s2 = float(res @ res) / dof
    info = jac.T @ jac
    if np.linalg.cond(info) > 1e12:      # a parameter at a bound the data cannot move
        sig = np.full(p.size, np.inf)
    else:
        sig = np.sqrt(np.clip(np.diag(s2 * np.linalg.inv(info)), 0.0, None))
    return FopdtFit(float(p[0]), float(p[1]), float(p[2]),
                    tuple(float(v) for v in p[3:3 + n_steps]), math.sqrt(s2),
                    float(sig[0]), float(sig[1]), float(sig[2]),
                    tuple(float(v) for v in sig[3:3 + n_steps]), int(res.size))
