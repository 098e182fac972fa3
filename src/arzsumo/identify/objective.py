"""The fitted parameters, the relative replay residual, and validation on held-out runs.

Residual. For run d, variable j (rho_h, v_h, rho_a, v_a), period k and position n with an
observed value, r = sqrt(w_j) (z_pred - z_obs) / s_{d,j}, with s_{d,j} the run's reference
scale (``ReplayData.scale``: the equilibrium value or the data's mean) and w_j a weight.
Unobserved values (NaN) are skipped. Where the replay twin stopped (left the physical
domain) the predicted value is missing; its residual is the finite ``penalty`` instead,
so the optimiser sees a large cost rather than an exception.

Parameters are optimised as z = log(p / p0), p0 the initial guess: all are positive,
their ranges span factors rather than offsets, and z = 0 at the guess makes a relative
finite-difference step mean the same for every parameter.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from arzsumo.identify.data import VARIABLES, IdentifyError, ReplayData
from arzsumo.identify.replay import ReplayOptions, run_replay
from arzsumo.identify.wave_target import WaveTarget
from arzsumo.model.params import ModelParameters

#: Parameters that can be identified, with default bounds (SI: m/s, -, -, s, m).
DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "v_free_h": (2.0, 50.0), "v_free_a": (2.0, 50.0),
    "ao_max_h": (0.1, 1.0), "ao_max_a": (0.1, 1.0),
    "gamma_h": (0.2, 8.0), "gamma_a": (0.2, 8.0),
    "tau_h": (0.5, 900.0), "tau_a": (0.5, 900.0),
    "spacing_h": (1.0, 60.0), "spacing_a": (1.0, 60.0),
    "wave_speed_h": (1.0, 30.0), "wave_speed_a": (1.0, 30.0), "corner": (1.0, 20.0),
}
#: The default selection: per-class fundamental diagram and relaxation times.
DEFAULT_WHICH = ("v_free_h", "v_free_a", "ao_max_h", "ao_max_a", "gamma_h", "gamma_a",
                 "tau_h", "tau_a")
#: The default selection per fundamental-diagram family (:mod:`arzsumo.model.fd`)
WHICH_BY_FAMILY: dict[str, tuple[str, ...]] = {
    "power": DEFAULT_WHICH,
    "newell": ("v_free_h", "v_free_a", "ao_max_h", "ao_max_a", "wave_speed_h",
               "wave_speed_a", "tau_h", "tau_a"),
}
#: Residual of a value the replay could not predict (the twin stopped), in scale units.
DEFAULT_PENALTY = 10.0
#: seconds between progress lines of a long fit (logged at INFO)
PROGRESS_EVERY = 60.0

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ParameterSpace:
    """The fitted parameter names, the guess, bounds and the log-scaled coordinates.

    Build it with :meth:`make`; ``z = log(p / p0)``.
    """

    guess: ModelParameters
    which: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def make(cls, guess: ModelParameters, which: Sequence[str],
             bounds: Mapping[str, tuple[float, float]] | None = None) -> ParameterSpace:
        """Validate ``which`` and ``bounds`` (physical units) against the guess."""
        which = tuple(which)
        if not which or len(set(which)) != len(which):
            raise IdentifyError(f"which = {list(which)} is not allowed: distinct names from "
                                f"{', '.join(DEFAULT_BOUNDS)}")
        if unknown := [n for n in which if n not in DEFAULT_BOUNDS]:
            raise IdentifyError(f"which = {unknown} is not allowed: names from "
                                f"{', '.join(DEFAULT_BOUNDS)}")
        if ignored := [n for n in which if n in guess.ignored_fields]:
            raise IdentifyError(f"which = {ignored} is not allowed: family = "
                                f"{guess.family!r} does not read them")
        given = dict(bounds or {})
        if extra := sorted(set(given) - set(which)):
            raise IdentifyError(f"bounds for {extra} are not allowed: only fitted parameters "
                                f"({', '.join(which)}) take bounds")
        lo, hi = [], []
        for name in which:
            b = given.get(name, DEFAULT_BOUNDS[name])
            low, high = (float(v) for v in b)
            value = getattr(guess, name)
            if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < high):
                raise IdentifyError(f"bounds[{name!r}] = {tuple(b)} is not allowed: "
                                    "0 < lower < upper, finite")
            if name.startswith("ao_max") and high > 1.0:
                raise IdentifyError(f"bounds[{name!r}] = {tuple(b)} is not allowed: an area "
                                    "occupancy at most 1")
            if not low <= value <= high:
                raise IdentifyError(f"initial guess {name} = {value:g} is outside its bounds "
                                    f"[{low:g}, {high:g}]; allowed: a guess within the bounds")
            lo.append(low)
            hi.append(high)
        return cls(guess, which, np.array(lo), np.array(hi))

    @property
    def p0(self) -> np.ndarray:
        """The guess of the fitted parameters (physical units)."""
        return np.array([getattr(self.guess, n) for n in self.which])

    def to_z(self, p: np.ndarray) -> np.ndarray:
        """Log coordinates z = log(p / p0)."""
        return np.log(np.asarray(p, float) / self.p0)

    def to_p(self, z: np.ndarray) -> np.ndarray:
        """Physical values p = p0 exp(z)."""
        return self.p0 * np.exp(np.asarray(z, float))

    def z_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds in z."""
        return self.to_z(self.lower), self.to_z(self.upper)

    def params(self, p: np.ndarray) -> ModelParameters:
        """The guess with the fitted parameters set to ``p`` (physical units)."""
        return self.guess.with_(**{n: float(v) for n, v in zip(self.which, p, strict=True)})


def check_datasets(datasets: Sequence[ReplayData]) -> tuple[ReplayData, ...]:
    """At least one :class:`ReplayData`."""
    runs = tuple(datasets)
    if not runs or not all(isinstance(d, ReplayData) for d in runs):
        raise IdentifyError(f"datasets = {len(runs)} item(s) is not allowed: one or more "
                            "ReplayData")
    return runs


def check_weights(weights: Sequence[float] | None) -> np.ndarray:
    """Weights of (rho_h, v_h, rho_a, v_a), >= 0, not all 0."""
    w = np.ones(4) if weights is None else np.asarray(weights, float)
    if w.shape != (4,) or not np.all(np.isfinite(w)) or w.min() < 0.0 or w.max() <= 0.0:
        raise IdentifyError(f"weights = {weights!r} is not allowed: 4 numbers >= 0 for "
                            f"({', '.join(VARIABLES)}), not all 0")
    return w


def relative_errors(data: ReplayData, predicted: np.ndarray,
                    penalty: float = DEFAULT_PENALTY) -> np.ndarray:
    """(z_pred - z_obs) / scale over the observed values, shape (T, 4, N), 0 elsewhere.

    Observed values the replay could not predict get ``penalty``.
    """
    err = (predicted - data.fields) / data.scale[None, :, None]
    err = np.where(np.isnan(err) & data.mask, penalty, err)
    return np.where(data.mask, err, 0.0)


class Objective:
    """Residual vector over all runs, for :func:`scipy.optimize.least_squares`; with a
    ``wave_target``, one more: its weighted wave-speed gap.

    Calling it with z runs the replay of every dataset; it counts evaluations and the
    replays that stopped (``failures``), keeps the smallest cost seen, and logs progress
    at most every :data:`PROGRESS_EVERY` seconds.
    """

    def __init__(self, space: ParameterSpace, datasets: Sequence[ReplayData],
                 weights: np.ndarray, options: ReplayOptions, penalty: float,
                 wave_target: WaveTarget | None = None) -> None:
        self.space, self.datasets = space, tuple(datasets)
        self.wave_target = wave_target
        self.sqrt_w = np.sqrt(weights)[None, :, None]
        self.options, self.penalty = options, penalty
        self.evaluations = self.failures = 0
        self.best = math.inf
        self._started = self._logged = time.perf_counter()

    def residuals_at(self, params: ModelParameters) -> np.ndarray:
        """Stacked weighted relative residuals of the observed values, for ``params``."""
        parts = []
        for data in self.datasets:
            run = run_replay(params, data, self.options)
            self.failures += run.stopped is not None
            err = relative_errors(data, run.fields, self.penalty) * self.sqrt_w
            parts.append(err[data.mask])
        self.evaluations += 1
        r = np.concatenate(parts)
        if self.wave_target is not None:    # lambda_4 at the measured equilibrium
            r = np.append(r, self.wave_target.residual(params, r.size))
        self.best = min(self.best, 0.5 * float(r @ r))
        now = time.perf_counter()
        if now - self._logged >= PROGRESS_EVERY:
            self._logged = now
            log.info("fit: %d evaluations in %.0f s, %d replays stopped, smallest cost %.6g",
                     self.evaluations, now - self._started, self.failures, self.best)
        return r

    def __call__(self, z: np.ndarray) -> np.ndarray:
        return self.residuals_at(self.space.params(self.space.to_p(z)))


@dataclass(frozen=True)
class ValidationReport:
    """Relative RMSE of the replay against each run (``names``), per variable."""

    names: tuple[str, ...]
    #: sqrt(mean((z_pred - z_obs)^2)) / scale per run and variable (runs, 4),
    #: dimensionless; periods after a twin stop count with the penalty
    rmse: np.ndarray
    #: the same over all runs' observed values together (4,)
    pooled: np.ndarray
    #: per run, the time (s) at which the replay stopped, None if it completed
    stopped: tuple[float | None, ...]


def validate(params: ModelParameters, datasets: Sequence[ReplayData],
             options: ReplayOptions | None = None,
             penalty: float = DEFAULT_PENALTY) -> ValidationReport:
    """Relative RMSE per run and variable of the replay under ``params`` (e.g. held-out runs)."""
    runs = check_datasets(datasets)
    opts = options if options is not None else ReplayOptions()
    sq, counts = np.zeros((len(runs), 4)), np.zeros((len(runs), 4))
    stopped = []
    for i, data in enumerate(runs):
        run = run_replay(params, data, opts)
        stopped.append(run.stopped)
        err = relative_errors(data, run.fields, penalty)
        sq[i] = (err ** 2).sum(axis=(0, 2))
        counts[i] = data.mask.sum(axis=(0, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        rmse = np.sqrt(sq / counts)
    pooled = np.sqrt(sq.sum(axis=0) / counts.sum(axis=0))
    return ValidationReport(tuple(d.name for d in runs), rmse, pooled, tuple(stopped))
