"""The critical occupancy of a loop's flow-occupancy curve, and ALINEA's target from it.

ALINEA (Papageorgiou et al. 1991) regulates its loop's occupancy to a target just below
the *critical occupancy* o_c, where the curve peaks (:data:`TARGET_SHARE` of it). On
period means (:func:`period_means`, ALINEA's resolution) :func:`fit_triangle` fits the
triangular curve q = q_c + s_f min(o - o_c, 0) + s_c max(o - o_c, 0), the shape of the
Daganzo-Newell diagram, by least squares over a grid of breakpoints o_c; :func:`binned_curve`
is the model-free cross-check. When the congested branch still rises (s_c > s_f / 2: the
loop never saw flow saturate), o_c is only a lower bound, the 98th percentile of the
occupancies, and ``saturated`` is False (docs/sumo.md, "The target").
Pure; SI: occupancy a fraction, flow veh/s, time s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from arzsumo.evaluation.authority import window_means

#: ALINEA's target as a share of the critical occupancy (just below it)
TARGET_SHARE = 0.9
#: width of the occupancy bins of the curve, fraction
BIN_WIDTH = 0.01


def period_means(occupancy: np.ndarray, flow: np.ndarray, dt: float, period: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Means of consecutive samples (each of ``dt`` s) over blocks of ``period`` s.

    Blocks with a missing (NaN) sample and a trailing incomplete block are dropped.
    Returns (occupancy, flow) per block.
    """
    n = round(period / dt)
    if n < 1 or abs(n * dt - period) > 1e-6:
        raise ValueError(f"period {period} s is not a whole multiple of {dt} s")
    o, f = window_means(occupancy, dt, period), window_means(flow, dt, period)
    keep = np.isfinite(o) & np.isfinite(f)
    return o[keep], f[keep]


def binned_curve(occupancy: np.ndarray, flow: np.ndarray, width: float = BIN_WIDTH
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean flow per occupancy bin of ``width``: (bin centres, mean flow, samples), for
    bins holding at least one sample."""
    occ, q = np.asarray(occupancy, float), np.asarray(flow, float)
    idx = np.floor(occ / width).astype(int)
    bins, count = np.unique(idx, return_counts=True)
    mean = np.array([q[idx == b].mean() for b in bins])
    return (bins + 0.5) * width, mean, count


@dataclass(frozen=True)
class TriangleFit:
    """Least-squares triangular curve: breakpoint ``critical`` (fraction), ``capacity``
    (veh/s) there, slopes of the free and congested branches (veh/s per unit occupancy)
    and the root-mean-square residual (veh/s)."""

    critical: float
    capacity: float
    free_slope: float
    congested_slope: float
    rmse: float

    def flow(self, occupancy: np.ndarray) -> np.ndarray:
        """The fitted curve's flow (veh/s) at ``occupancy`` (fractions)."""
        d = np.asarray(occupancy, float) - self.critical
        return self.capacity + self.free_slope * np.minimum(d, 0) + \
            self.congested_slope * np.maximum(d, 0)


def fit_triangle(occupancy: np.ndarray, flow: np.ndarray, grid: int = 200) -> TriangleFit:
    """Fit q = q_c + s_f min(o - o_c, 0) + s_c max(o - o_c, 0) (module docstring) with
    o_c on ``grid`` points between the 2nd and 98th percentiles of the occupancies."""
    occ, q = np.asarray(occupancy, float), np.asarray(flow, float)
    if occ.size < 5:
        raise ValueError(f"{occ.size} samples: at least 5 are needed to fit a curve")
    lo, hi = np.percentile(occ, [2.0, 98.0])

    def solve(c: float) -> tuple[float, np.ndarray]:
        a = np.column_stack([np.ones_like(occ), np.minimum(occ - c, 0.0),
                             np.maximum(occ - c, 0.0)])
        coef, *_ = np.linalg.lstsq(a, q, rcond=None)
        return float(np.sum((a @ coef - q) ** 2)), coef

    fits = [(*solve(float(c)), float(c)) for c in np.linspace(lo, hi, grid)]
    sse, coef, c = min(fits, key=lambda f: f[0])
    return TriangleFit(c, float(coef[0]), float(coef[1]), float(coef[2]),
                       math.sqrt(sse / occ.size))


@dataclass(frozen=True)
class CriticalOccupancy:
    """The loop's critical occupancy and ALINEA's suggested target (fractions).

    ``fit`` is the triangular fit, ``peak_bin`` the centre of the occupancy bin of the
    highest mean flow (bins of at least ``min_count`` samples), ``saturated`` whether the
    data show flow saturating (then ``critical`` is the fit's breakpoint; otherwise the
    lower bound of the module docstring), ``samples`` the number of period means used.
    """

    critical: float
    target: float
    share: float
    fit: TriangleFit
    peak_bin: float
    saturated: bool
    samples: int


def critical_occupancy(occupancy: np.ndarray, flow: np.ndarray,
                       share: float = TARGET_SHARE, width: float = BIN_WIDTH,
                       min_count: int = 3) -> CriticalOccupancy:
    """The critical occupancy of period-mean samples (occupancy fraction, flow veh/s)
    and the target ``share`` x o_c (module docstring)."""
    if not 0 < share <= 1:
        raise ValueError(f"share {share} is not in (0, 1]")
    fit = fit_triangle(occupancy, flow)
    centres, mean, count = binned_curve(occupancy, flow, width)
    ok = count >= min_count
    peak = float(centres[ok][np.argmax(mean[ok])]) if ok.any() else math.nan
    saturated = fit.free_slope > 0 and fit.congested_slope < 0.5 * fit.free_slope
    critical = fit.critical if saturated else float(np.percentile(occupancy, 98.0))
    return CriticalOccupancy(critical, share * critical, share, fit, peak, bool(saturated),
                             int(np.asarray(occupancy).size))
