"""The fit: bounded nonlinear least squares of the replay residual, with uncertainties.

:func:`identify` minimises the stacked relative replay residual of several runs
(:mod:`arzsumo.identify.objective`) with :func:`scipy.optimize.least_squares` (trust-region
reflective, bounds, forward-difference Jacobian) in the log coordinates z = log(p / p0).

Uncertainty. With J the Jacobian of the residual in z at the optimum, m residuals, n
parameters and s^2 = sum(r^2) / (m - n), the covariance of z is s^2 (J^T J)^-1
(pseudo-inverse where J is rank deficient), that of p cov_p = diag(p) cov_z diag(p) (delta
method): a lower bound where model error, not noise, dominates, as on SUMO data. The
optional seeded bootstrap refits on runs drawn with replacement; its spread also carries
the run-to-run variation.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

from arzsumo.identify.data import IdentifyError, ReplayData
from arzsumo.identify.objective import (
    DEFAULT_PENALTY,
    DEFAULT_WHICH,
    Objective,
    ParameterSpace,
    ValidationReport,
    check_datasets,
    check_weights,
    validate,
)
from arzsumo.identify.replay import ReplayOptions
from arzsumo.identify.wave_target import WaveTarget
from arzsumo.model.params import ModelParameters

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class FitSettings:
    """Settings of :func:`scipy.optimize.least_squares` and of the bootstrap."""

    #: largest number of residual evaluations outside the Jacobian (scipy's count)
    max_nfev: int = 40
    #: forward-difference step in z, i.e. a relative step of the parameters (1e-3: the
    #: replay is continuous in the parameters but its adaptive time step adds noise of
    #: about 1e-6 relative, which a much smaller step would amplify)
    diff_step: float = 1e-3
    #: scipy's stopping tolerances
    ftol: float = 1e-6
    xtol: float = 1e-6
    gtol: float = 1e-8
    #: characteristic change of z (1: parameters move by factors of order e)
    x_scale: float = 1.0
    #: bootstrap refits over runs (0: none), and the seed of their draws
    bootstrap: int = 0
    seed: int = 0

    def __post_init__(self) -> None:
        for name, least in (("max_nfev", 1), ("bootstrap", 0)):
            value = getattr(self, name)
            if not isinstance(value, int) or value < least:
                raise IdentifyError(f"{name} = {value!r} is not allowed: an integer >= {least}")
        for name in ("diff_step", "ftol", "xtol", "gtol", "x_scale"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and 0.0 < value < np.inf):
                raise IdentifyError(f"{name} = {value!r} is not allowed: a number > 0")


@dataclass(frozen=True)
class IdentificationResult:
    """The identified parameters, their uncertainties and the cost of the fit."""

    #: the guess with the fitted parameters replaced
    params: ModelParameters
    #: the fitted parameters, in the order of the arrays below
    which: tuple[str, ...]
    #: fitted values and 1-sigma uncertainties from the Jacobian (n,), SI units
    values: np.ndarray
    sigma: np.ndarray
    #: correlation matrix of the fitted parameters (n, n), from the same covariance
    correlation: np.ndarray
    #: parameters that ended on a bound (their sigma is not meaningful), (n,) bool
    at_bound: np.ndarray
    #: refitted values (B, n), one row per bootstrap draw of runs
    bootstrap: np.ndarray | None
    #: relative RMSE per run and variable on the training runs at the optimum
    training: ValidationReport
    #: half the sum of squared residuals at the optimum
    cost: float
    #: number of residuals m (observed values over all runs)
    residuals: int
    #: scipy's count of residual evaluations (without those of the Jacobian)
    nfev: int
    #: all residual evaluations, Jacobian columns included (each replays every run)
    evaluations: int
    #: seconds for the fit (bootstrap excluded)
    wall_time: float
    #: replays that stopped (twin outside the physical domain) during the fit
    failures: int
    #: scipy's status and message
    success: bool
    message: str

    @property
    def bootstrap_sigma(self) -> np.ndarray | None:
        """Standard deviation of the bootstrap refits (n,), or None."""
        if self.bootstrap is None or len(self.bootstrap) < 2:
            return None
        return np.std(self.bootstrap, axis=0, ddof=1)


def covariance(jac: np.ndarray, residuals: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Covariance of the parameters p (n,), s^2 (J^T J)^-1 in z mapped to p (module doc)."""
    m, n = jac.shape
    s2 = float(residuals @ residuals) / max(m - n, 1)
    cov_z = s2 * np.linalg.pinv(jac.T @ jac)
    return cov_z * np.outer(p, p)


def _solve(objective: Objective, z0: np.ndarray, settings: FitSettings) -> OptimizeResult:
    lo, hi = objective.space.z_bounds()
    return least_squares(objective, np.clip(z0, lo, hi), jac="2-point", bounds=(lo, hi),
                         method="trf", x_scale=settings.x_scale, diff_step=settings.diff_step,
                         max_nfev=settings.max_nfev, ftol=settings.ftol, xtol=settings.xtol,
                         gtol=settings.gtol)


def _bootstrap(space: ParameterSpace, runs: tuple[ReplayData, ...], z_opt: np.ndarray,
               weights: np.ndarray, options: ReplayOptions, penalty: float,
               settings: FitSettings, target: WaveTarget | None = None) -> np.ndarray:
    """Refits on runs drawn with replacement, started at the optimum; (B, n) values."""
    rng = np.random.default_rng(settings.seed)
    rows = []
    for b in range(settings.bootstrap):
        pick = rng.integers(0, len(runs), size=len(runs))
        obj = Objective(space, [runs[i] for i in pick], weights, options, penalty, target)
        rows.append(space.to_p(_solve(obj, z_opt, settings).x))
        log.info("bootstrap %d/%d on runs %s: %s", b + 1, settings.bootstrap, pick.tolist(),
                 np.array2string(rows[-1], precision=4))
    return np.array(rows)


def identify(datasets: Sequence[ReplayData], initial_guess: ModelParameters,
             bounds: Mapping[str, tuple[float, float]] | None = None,
             which: Sequence[str] = DEFAULT_WHICH, weights: Sequence[float] | None = None,
             *, options: ReplayOptions | None = None, settings: FitSettings | None = None,
             penalty: float = DEFAULT_PENALTY, wave_target: WaveTarget | None = None
             ) -> IdentificationResult:
    """Fit the model parameters ``which`` to the runs ``datasets`` by replay least squares.

    Parameters
    ----------
    datasets : sequence of ReplayData
        Training runs, fitted together.
    initial_guess : ModelParameters
        Start of the fit; the parameters not in ``which`` stay as they are here.
    bounds : mapping name -> (lower, upper), optional
        Physical units (m/s, -, -, s, m); default
        :data:`arzsumo.identify.objective.DEFAULT_BOUNDS`. The guess must lie within.
    which : sequence of str
        Parameters to fit (names of :class:`ModelParameters` fields; see
        :data:`arzsumo.identify.objective.DEFAULT_BOUNDS` for those allowed).
    weights : 4 floats, optional
        Weights of the residuals of (rho_h, v_h, rho_a, v_a); default all 1.
    options : ReplayOptions, optional
        Numerics of the replay twin.
    penalty : float
        Residual (in scale units) of a value the replay could not predict.
    wave_target : WaveTarget, optional
        A measured wave speed lambda_4 should match: one more residual (its module).
    """
    runs = check_datasets(datasets)
    space = ParameterSpace.make(initial_guess, which, bounds)
    w = check_weights(weights)
    opts = options if options is not None else ReplayOptions()
    cfg = settings if settings is not None else FitSettings()
    if not (isinstance(penalty, int | float) and 0.0 < penalty < np.inf):
        raise IdentifyError(f"penalty = {penalty!r} is not allowed: a number > 0")
    objective = Objective(space, runs, w, opts, float(penalty), wave_target)
    start = time.perf_counter()
    res = _solve(objective, np.zeros(len(space.which)), cfg)
    wall = time.perf_counter() - start
    p = space.to_p(res.x)
    cov = covariance(res.jac, res.fun, p)
    sigma = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr, params = cov / np.outer(sigma, sigma), space.params(p)
    log.info("identified %s in %.1f s (%d evaluations, %d twin failures): %s",
             ", ".join(space.which), wall, objective.evaluations, objective.failures,
             res.message)
    boot = (_bootstrap(space, runs, res.x, w, opts, float(penalty), cfg, wave_target)
            if cfg.bootstrap > 0 else None)
    return IdentificationResult(
        params, space.which, p, sigma, corr, res.active_mask != 0, boot,
        validate(params, runs, opts, penalty), float(res.cost), int(res.fun.size),
        int(res.nfev), objective.evaluations, wall, objective.failures, bool(res.success),
        str(res.message))
