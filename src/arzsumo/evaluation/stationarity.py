"""Is a run stationary? The trend of the section's vehicle count over a window.

On block means of the section's vehicle count (30 s by default: longer than most of the
autocorrelation of SUMO's waves, short enough to leave 15 blocks in a 450 s horizon): the
OLS slope with its 95 % t-interval, Kendall's tau test against time (no assumption of
linearity or normality) and the drift; docs/outputs.md, ``section_trend``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy import stats

#: thresholds of :attr:`CountTrend.stationary`
KENDALL_ALPHA, MAX_DRIFT = 0.05, 0.10


@dataclass(frozen=True)
class CountTrend:
    """Trend of a count series on block means (veh/min; drift and p dimensionless)."""

    slope_veh_min: float
    slope_lo: float
    slope_hi: float
    kendall_p: float
    drift: float
    mean_veh: float
    blocks: int
    block_s: float

    @property
    def stationary(self) -> bool:
        """Kendall's p > 0.05 and |drift| < 10 %."""
        return bool(self.kendall_p > KENDALL_ALPHA and abs(self.drift) < MAX_DRIFT)

    def as_dict(self) -> dict[str, float | int | bool]:
        return {**asdict(self), "stationary": self.stationary}


def count_trend(count: np.ndarray, dt: float, block_s: float = 30.0) -> CountTrend:
    """The trend of ``count`` (veh, one sample every ``dt`` s) on ``block_s`` block means.

    Needs at least 3 complete blocks; NaN samples are refused (ValueError).
    """
    n = np.asarray(count, float)
    if not np.all(np.isfinite(n)):
        raise ValueError("count has NaN or infinite samples")
    per = max(1, round(block_s / dt))
    nb = n.size // per
    if nb < 3:
        raise ValueError(f"{n.size} samples of {dt} s make {nb} blocks of {block_s} s; "
                         "expected at least 3")
    blocks = n[: nb * per].reshape(nb, per).mean(axis=1)
    t_min = (np.arange(nb) + 0.5) * per * dt / 60.0
    fit = stats.linregress(t_min, blocks)
    half = float(stats.t.ppf(0.975, nb - 2) * fit.stderr)
    kendall = stats.kendalltau(t_min, blocks)
    mean = float(n.mean())
    drift = float(fit.slope * (n.size * dt / 60.0) / mean) if mean > 0 else math.nan
    p = float(kendall.pvalue) if np.isfinite(kendall.pvalue) else 1.0   # constant series
    return CountTrend(float(fit.slope), float(fit.slope) - half, float(fit.slope) + half, p,
                      drift, mean, int(nb), per * dt)
