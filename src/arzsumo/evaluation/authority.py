"""How much of the law's boundary input reached the boundary: the actuator's authority.

The U applied (clpsys4) and the outflow q(L) of a run's periods, on means over windows
(a meter's one-period outflow is 0 or a few vehicles): their sd and the *realised gain*,
the slope of the one on the other, 1 on a unit actuator without dead time; in closed loop
a diagnostic, not an identification (docs/outputs.md, ``actuation.authority``; docs/sumo.md,
"Actuation limits"). Pure. SI: s, veh/s.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike


def window_means(values: ArrayLike, period: float, window: float) -> np.ndarray:
    """Means of ``values`` (one per control period of ``period`` s) over consecutive
    windows of ``window`` s, the incomplete last window dropped."""
    v = np.asarray(values, float)
    per = max(1, round(window / period))
    n = v.size // per
    return v[: n * per].reshape(n, per).mean(axis=1)


@dataclass(frozen=True)
class Authority:
    """The sd (veh/s) of the U applied and of the outflow over windows of ``window_s``, the
    realised gain (dimensionless) and its standard error; NaN where U did not move."""

    window_s: float
    u_sd: float
    outflow_sd: float
    gain: float
    gain_se: float
    windows: int

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)


def authority(u_applied: ArrayLike, outflow: ArrayLike, period: float,
              window: float = 60.0) -> Authority:
    """The :class:`Authority` of a run's periods: ``u_applied`` and ``outflow`` (veh/s,
    one per control period of ``period`` s), on means over ``window`` s."""
    u = window_means(u_applied, period, window)
    q = window_means(outflow, period, window)
    n = u.size
    u_sd = float(np.std(u, ddof=1)) if n > 1 else math.nan
    q_sd = float(np.std(q, ddof=1)) if n > 1 else math.nan
    if n < 3 or not u_sd > 0:
        return Authority(window, u_sd, q_sd, math.nan, math.nan, n)
    du, dq = u - u.mean(), q - q.mean()
    sxx = float(du @ du)
    gain = float(du @ dq) / sxx
    resid = dq - gain * du
    se = math.sqrt(float(resid @ resid) / (n - 2) / sxx)
    return Authority(window, u_sd, q_sd, gain, se, n)
