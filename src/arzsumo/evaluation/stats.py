"""Statistics over seeds: means with confidence intervals, paired differences, wins.

Pure numpy/scipy. Controllers are compared on the *same* seeds: the paired difference
``d_i = treatment_i - baseline_i`` (seed i), whose mean gets a Student-t and a seeded
(reproducible) BCa or percentile bootstrap 95 % interval. Conventions of every function:

* **NaN** values are *dropped*, pair-wise for paired data (a seed whose run failed or
  whose measure is undefined leaves both members out), and the number dropped is kept
  in the result (``n_dropped``). Infinite values are refused (:class:`StatisticsError`).
* **n = 1**: the interval is undefined; its bounds are NaN (``interval_defined`` is
  False). n = 0 (everything dropped) is refused.
* **Zero variance**: the interval has zero width (both methods). Samples whose spread is
  at most ``1e-12`` times their largest magnitude count as constant, because ``a - b``
  of a constant shift differs from the shift by float rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats as sps

from arzsumo.errors import ArzsumoError

#: Relative spread below which a sample counts as constant (float rounding of a - b).
CONSTANT_RTOL = 1e-12
BOOTSTRAP_METHODS = ("BCa", "percentile")


class StatisticsError(ArzsumoError, ValueError):
    """Data that the statistics cannot use (shape, infinite values, nothing left)."""


@dataclass(frozen=True)
class MeanCI:
    """Mean of a sample with a two-sided confidence interval.

    ``mean``, ``low``, ``high`` in the unit of the data (NaN bounds when n = 1); ``n``
    values used and ``n_dropped`` NaN values left out; confidence ``level`` (e.g. 0.95);
    ``method``: ``"t"``, ``"BCa"`` or ``"percentile"``.
    """

    mean: float
    low: float
    high: float
    n: int
    n_dropped: int = 0
    level: float = 0.95
    method: str = "t"

    def __post_init__(self) -> None:
        if self.n < 1:
            raise StatisticsError(f"n = {self.n} is not allowed: at least 1 value")
        if not 0.0 < self.level < 1.0:
            raise StatisticsError(f"level = {self.level} is not allowed: a number in (0, 1)")

    @property
    def interval_defined(self) -> bool:
        """False when the interval cannot be computed (n = 1)."""
        return not (math.isnan(self.low) or math.isnan(self.high))

    @property
    def width(self) -> float:
        """high - low (NaN when undefined)."""
        return self.high - self.low

    def covers(self, value: float) -> bool:
        """True when ``low <= value <= high``."""
        return self.interval_defined and self.low <= value <= self.high


@dataclass(frozen=True)
class PairedComparison:
    """Treatment minus baseline over the same seeds: the mean paired difference with its
    Student-t (``t``) and ``bootstrap`` intervals, and the seeds where the treatment is
    better (``wins``), worse (``losses``) or within ``tie_tol`` of the baseline (``ties``);
    better means lower when ``lower_is_better`` (delays, times, fuel).
    """

    t: MeanCI
    bootstrap: MeanCI
    wins: int
    losses: int
    ties: int
    lower_is_better: bool = True

    @property
    def mean_diff(self) -> float:
        """Mean of treatment - baseline, in the unit of the data."""
        return self.t.mean

    @property
    def n(self) -> int:
        return self.t.n


def _clean(x: ArrayLike, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``x`` as a 1-d float array and its NaN mask; infinite values refused."""
    a = np.asarray(x, dtype=float)
    if a.ndim != 1:
        raise StatisticsError(f"{name} has shape {a.shape}; expected one value per seed")
    if np.isinf(a).any():
        raise StatisticsError(f"{name} = {a.tolist()} is not allowed: finite values or NaN")
    return a, np.isnan(a)


def _is_constant(a: np.ndarray) -> bool:
    scale = float(np.max(np.abs(a))) if a.size else 0.0
    return float(np.ptp(a)) <= CONSTANT_RTOL * scale


def _kept(x: ArrayLike) -> tuple[np.ndarray, int]:
    """The values of ``x`` that are not NaN, and how many were; nothing left refused."""
    a, nan = _clean(x, "x")
    if nan.all():
        raise StatisticsError(f"x = {a.tolist()} is not allowed: at least one value not NaN")
    return a[~nan], int(nan.sum())


def _t_interval(a: np.ndarray, level: float) -> tuple[float, float, float]:
    """Mean and Student-t interval of ``a`` (NaN bounds for one value)."""
    mean = float(np.mean(a))
    if a.size == 1:
        return mean, math.nan, math.nan
    if _is_constant(a):
        return mean, mean, mean
    half = float(sps.t.ppf(0.5 + level / 2, a.size - 1) * np.std(a, ddof=1) / math.sqrt(a.size))
    return mean, mean - half, mean + half


def mean_ci(x: ArrayLike, level: float = 0.95) -> MeanCI:
    """Mean of ``x`` (one value per seed; NaN dropped and counted) with its Student-t
    confidence interval: NaN bounds when one value is left, zero width for constant data."""
    kept, dropped = _kept(x)
    mean, low, high = _t_interval(kept, level)
    return MeanCI(mean, low, high, int(kept.size), dropped, level, "t")


def bootstrap_mean_ci(x: ArrayLike, level: float = 0.95, *, method: str = "BCa",
                      n_resamples: int = 9999, seed: int = 0) -> MeanCI:
    """Mean of ``x`` with a seeded bootstrap confidence interval (scipy.stats.bootstrap).

    NaN values are dropped and counted. One value gives NaN bounds, constant data a
    zero-width interval (the bootstrap distribution is degenerate there; scipy's BCa
    would return NaN).
    """
    if method not in BOOTSTRAP_METHODS:
        raise StatisticsError(f"method = {method!r} is not allowed: one of {BOOTSTRAP_METHODS}")
    kept, dropped = _kept(x)
    mean = float(np.mean(kept))
    if kept.size == 1:
        low = high = math.nan
    elif _is_constant(kept):
        low = high = mean
    else:
        res = sps.bootstrap((kept,), np.mean, n_resamples=n_resamples, method=method,
                            confidence_level=level, rng=np.random.default_rng(seed),
                            vectorized=True)
        low, high = float(res.confidence_interval.low), float(res.confidence_interval.high)
    return MeanCI(mean, low, high, int(kept.size), dropped, level, method)


def wins_losses(diff: ArrayLike, *, lower_is_better: bool = True,
                tie_tol: float = 0.0) -> tuple[int, int, int]:
    """(wins, losses, ties) of the treatment from paired differences treatment - baseline.

    A seed is a tie when ``|diff| <= tie_tol``; NaN differences are not counted.
    """
    d, nan = _clean(diff, "diff")
    d = d[~nan]
    better = -d if lower_is_better else d
    ties = int(np.sum(np.abs(d) <= tie_tol))
    wins = int(np.sum(better > tie_tol))
    return wins, int(d.size) - wins - ties, ties


def paired_difference(treatment: ArrayLike, baseline: ArrayLike, *, level: float = 0.95,
                      lower_is_better: bool = True, tie_tol: float = 0.0,
                      method: str = "BCa", n_resamples: int = 9999,
                      seed: int = 0) -> PairedComparison:
    """Treatment minus baseline over the same seeds, with t and bootstrap intervals.

    ``treatment`` and ``baseline``: the measure per seed, same seed order and unit; seeds
    where either is NaN are dropped and counted in ``n_dropped``. With ``lower_is_better``
    a win is ``treatment < baseline - tie_tol``; ``|d| <= tie_tol`` is a tie. ``method``
    ("BCa" or "percentile"), ``n_resamples`` and ``seed`` are the bootstrap's.
    """
    t, t_nan = _clean(treatment, "treatment")
    b, b_nan = _clean(baseline, "baseline")
    if t.shape != b.shape:
        raise StatisticsError(f"treatment has {t.size} values and baseline {b.size}; "
                              "expected one value per seed for both, same seeds")
    d = t - b
    d[t_nan | b_nan] = math.nan
    return PairedComparison(mean_ci(d, level),
                            bootstrap_mean_ci(d, level, method=method,
                                              n_resamples=n_resamples, seed=seed),
                            *wins_losses(d, lower_is_better=lower_is_better, tie_tol=tie_tol),
                            lower_is_better=lower_is_better)
