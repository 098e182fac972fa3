"""The actuator's gain read from the staircase's levels, not from its steps.

A step's gain dq / dr divides the difference of two level means by a small step
(200 veh/h = 0.056 veh/s) against per-second outflow counts whose residual sd is near
0.8 veh/s: each per-step gain carries the noise of two levels, consecutive steps share
a level, and a 95 % interval over a dozen steps is 1-2 wide where the gate asks for 0.6.
Pooling the levels instead uses each level once, over the whole of its hold after the
response has settled:

* per hold (between consecutive step times, or the record's ends) the means of q and
  r over the bins after ``settle_s`` (the dead time and a few time constants);
* per *side* of the nominal rate (the lead-in level's): ``up`` takes the levels at or
  above it, ``down`` those at or below, so that each side asks whether the meter moves
  q(L) below or above q*, the two signs of the paper's U;
* the gain by least squares with one intercept per record (the seeds' operating points
  differ), q_k = a_record + g r_k; its 95 % interval from the residuals, Student's t
  with n - records - 1 degrees of freedom (levels of one record are treated as
  independent: holds of two minutes and more outlast the counts' correlation).

SI units: s, veh/s; gains veh/s per veh/s (1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from scipy import stats

from arzsumo.errors import require
from arzsumo_studies.gates.gates import PremiseError

#: the part of each hold left out of its level: dead time plus a few time constants, s
SETTLE_S = 30.0
SIDES = ("up", "down")


@dataclass(frozen=True)
class LevelFit:
    """One side's gain from the levels: ``side``, ``levels`` and ``records`` used, the
    ``gain`` (1) with its 95 % interval ``gain_low``, ``gain_high`` (NaN without a
    degree of freedom) and the residual sd of the levels ``residual_sd`` (veh/s)."""

    side: str
    levels: int
    records: int
    gain: float
    gain_low: float
    gain_high: float
    residual_sd: float

    @property
    def halfwidth(self) -> float:
        """Half the 95 % interval's width (NaN without one)."""
        return (self.gain_high - self.gain_low) / 2


def hold_levels(t: np.ndarray, q: np.ndarray, r: np.ndarray, step_times: Sequence[float],
                settle_s: float = SETTLE_S) -> tuple[np.ndarray, np.ndarray]:
    """(q, r) per hold, lead-in first: the means over each hold's bins that end more
    than ``settle_s`` (at most half the hold) after it starts (bin ends ``t``, s; bin
    means q, r, veh/s)."""
    dt = float(t[1] - t[0])
    edges = (float(t[0]) - dt, *step_times, float(t[-1]))
    qs, rs = [], []
    for start, end in pairwise(edges):
        settle = min(settle_s, (end - start) / 2)        # a short hold: its second half
        m = (t > start + settle + 1e-9) & (t <= end + 1e-9)
        require(int(m.sum()) >= 2, "step_times", f"a hold ({start:g}, {end:g}] s",
                "holds of at least four bins", PremiseError)
        qs.append(float(q[m].mean()))
        rs.append(float(r[m].mean()))
    return np.array(qs), np.array(rs)


def _nan_fit(side: str, levels: int, records: int) -> LevelFit:
    return LevelFit(side, levels, records, math.nan, math.nan, math.nan, math.nan)


def side_fit(levels: Sequence[tuple[np.ndarray, np.ndarray]], side: str) -> LevelFit:
    """The gain of one ``side`` (``"up"`` or ``"down"``) from per-record levels
    ``(q, r)`` (:func:`hold_levels`), each record's lead-in level its nominal rate."""
    require(side in SIDES, "side", side, " or ".join(SIDES), PremiseError)
    xs, ys = [], []
    for q, r in levels:
        tol = 1e-9 * max(abs(float(r[0])), 1e-12)
        keep = r >= r[0] - tol if side == "up" else r <= r[0] + tol
        if keep.sum() < 2 or np.ptp(r[keep]) <= tol:
            continue
        xs.append(r[keep] - r[keep].mean())
        ys.append(q[keep] - q[keep].mean())
    n, k = sum(x.size for x in xs), len(xs)
    if k == 0:
        return _nan_fit(side, n, k)
    x, y = np.concatenate(xs), np.concatenate(ys)
    gain = float(x @ y / (x @ x))
    dof = n - k - 1
    if dof < 1:
        return LevelFit(side, n, k, gain, math.nan, math.nan, math.nan)
    sd = float(math.sqrt(np.sum((y - gain * x) ** 2) / dof))
    half = float(stats.t.ppf(0.975, dof)) * sd / math.sqrt(float(x @ x))
    return LevelFit(side, n, k, gain, gain - half, gain + half, sd)
