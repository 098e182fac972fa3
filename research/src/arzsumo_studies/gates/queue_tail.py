"""Where the queue's tail stands: the free-flowing stretch at the section's inlet.

The paper's section is congested over its whole length (lambda_4 < 0 everywhere, section
2). When SUMO's queue tail stands inside the section instead, the cells upstream of it
ride in free flow, and the amplitude of the speed fluctuations there measures the
passage between free and congested traffic, not a wave that grew: the amplification
(upstream over downstream amplitude) then reads growth where there is none. The tail is
read off the speed field: a cell is free when its mean speed over the periods given
exceeds ``ratio`` times that of the last ``reference`` cells (the merge congests the
section's downstream end), and the tail is the downstream edge of the free cells that
run on from x = 0 (0 when the first cell is congested; a cell no vehicle visited takes
its upstream neighbour's state). SI units: m, m/s.
"""

from __future__ import annotations

import numpy as np

from arzsumo.errors import require
from arzsumo_studies.gates.gates import PremiseError

#: a cell rides free above this multiple of the median cell speed
FREE_RATIO = 1.5


def queue_tail(x: np.ndarray, v: np.ndarray, ratio: float = FREE_RATIO,
               reference: int = 3) -> float:
    """The queue tail's position (m): the downstream edge of the free cells from x = 0.

    Parameters
    ----------
    x : ndarray (C,)
        Cell centres, m, increasing, uniform.
    v : ndarray (T, C)
        Speeds per period and cell, m/s (NaN: no vehicle).
    ratio : float
        A cell is free when its mean speed exceeds ``ratio`` times the reference's.
    reference : int
        The downstream cells whose mean speed is the congested reference.
    """
    x, v = np.asarray(x, float), np.atleast_2d(np.asarray(v, float))
    require(x.ndim == 1 and x.size >= 2 and v.shape[1] == x.size, "v", v.shape,
            f"periods x {x.size} cells", PremiseError)
    require(ratio > 1.0, "ratio", ratio, "above 1", PremiseError)
    with np.errstate(invalid="ignore"):
        means = np.array([np.nanmean(c) if np.isfinite(c).any() else np.nan for c in v.T])
    congested = means[-reference:]
    if not np.isfinite(congested).any() or not np.isfinite(means[0]):
        return 0.0
    free = means > ratio * np.nanmean(congested)
    for k in range(1, free.size):          # an empty cell continues its neighbour's state
        if not np.isfinite(means[k]):
            free[k] = free[k - 1]
    if not free[0]:
        return 0.0
    last = int(np.argmin(free)) - 1 if not free.all() else x.size - 1
    dx = float(x[1] - x[0])
    return float(x[last] + dx / 2)
