"""Gate 4, the actuator: does the ramp meter move the outflow q(L) both ways?

The paper's input U(t) is the perturbation of the outflow at x = L (section 2, the
boundary condition at x = L), "implemented by the ramp metering"; the backstepping law
asks for U of either sign. On the ramp network the meter moves q(L) through the merge:
releasing ramp vehicles faster takes merge capacity from the mainline, so the gain
dq(L) / dr of the mainline outflow on the release rate r is near -1 when the merge is at
capacity. The gate steps r by +-200 veh/h and asks for that gain in *both* directions:
a meter that moves q(L) only one way cannot apply the law's U.

Per step at t0 (:func:`step_measures`): the levels of q and r are the means over the
last ``level_s`` before t0 and before the next step (or the record's end); dq / dr is
the step's gain. Per direction (:func:`direction_fit`; up = r increases): the gain
pooled by least squares through the origin, sum(dq dr) / sum(dr^2), and the 95 %
interval of the per-step gains. The dead time comes from the method of areas (Astrom and
Hagglund) for a first order plus dead time response, robust to the noise of counts
because it integrates: A0 = int (q_inf - q) dt = dq (theta + T) gives the apparent dead
time theta + T, and A1 = int_0^{theta + T} (q - q0) dt = dq T / e gives T. For an exact
FOPDT step response theta + T is exact (integrals over whole bins, the samples being bin
means); theta and T are exact when T spans a few bins, and within half a bin when the
response rises within one (A1 is interpolated linearly inside a bin).

Samples are bin means over (t - dt, t] (counts per bin over dt, as SUMO's per-second
counts are), on a uniform grid; step times should lie on bin edges (otherwise the dead
time is off by up to one bin). A hold should last at least ``level_s`` plus the
response's own time (theta + 5 T). SI units: s, veh/s; gains veh/s per veh/s (1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from itertools import pairwise

import numpy as np

from arzsumo.errors import require
from arzsumo.evaluation.stats import mean_ci
from arzsumo_studies.gates.actuator_levels import (
    SETTLE_S,
    SIDES,
    LevelFit,
    hold_levels,
    side_fit,
)
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds

#: the level windows at the end of each hold, s
LEVEL_S = 60.0


@dataclass(frozen=True)
class ActuatorRecord:
    """One run's outflow and commanded release rate around steps of the rate.

    Attributes
    ----------
    t : ndarray (T,)
        Bin ends, s, uniform.
    q : ndarray (T,)
        Mainline outflow at x = L, mean over each bin, veh/s.
    r : ndarray (T,)
        Commanded ramp release rate in each bin, veh/s.
    step_times : tuple of float
        Times of the rate's steps, s, increasing, inside the record.
    """

    t: np.ndarray
    q: np.ndarray
    r: np.ndarray
    step_times: tuple[float, ...]

    def __post_init__(self) -> None:
        t, q, r = (np.asarray(a, float).ravel() for a in (self.t, self.q, self.r))
        steps = tuple(float(s) for s in np.atleast_1d(self.step_times))
        require(t.size >= 4 and q.shape == t.shape == r.shape, "q", q.shape,
                f"one outflow and one rate per time ({t.size} times, at least 4)",
                PremiseError)
        require(bool(np.isfinite(t).all() & np.isfinite(q).all() & np.isfinite(r).all()),
                "q", "non-finite values", "finite times, outflows and rates", PremiseError)
        dt = np.diff(t)
        require(bool(dt.min() > 0 and np.ptp(dt) <= 1e-6 * dt.mean()), "t", "irregular",
                "uniform, increasing bin ends", PremiseError)
        require(len(steps) >= 1 and all(t[0] < s < t[-1] for s in steps)
                and all(b > a for a, b in pairwise(steps)),
                "step_times", steps, f"increasing times inside ({t[0]}, {t[-1]}) s",
                PremiseError)
        for name, v in (("t", t), ("q", q), ("r", r), ("step_times", steps)):
            object.__setattr__(self, name, v)

    @property
    def dt(self) -> float:
        """Bin width, s."""
        return float(self.t[1] - self.t[0])


@dataclass(frozen=True)
class StepMeasure:
    """One step of the release rate: its size, the outflow's answer and the areas.

    ``t0`` (s), ``dr`` and ``dq`` (veh/s), ``gain`` = dq / dr (1), ``direction``
    (``"up"`` when dr > 0), ``area0`` = int (q_inf - q) dt over the hold (veh),
    ``since`` (s after t0, bin ends of the hold) and ``cumulative`` (int (q - q0) dt up to
    each, veh).
    """

    t0: float
    dr: float
    dq: float
    gain: float
    direction: str
    area0: float
    since: np.ndarray
    cumulative: np.ndarray


def _level(t: np.ndarray, y: np.ndarray, end: float, span: float) -> float:
    """Mean of y over the bins ending in (end - span, end]."""
    m = (t > end - span + 1e-9) & (t <= end + 1e-9)
    require(int(m.sum()) >= 2, "step_times", f"a level window ending at {end} s",
            "holds of at least two bins before and after each step", PremiseError)
    return float(y[m].mean())


def step_measures(record: ActuatorRecord, level_s: float = LEVEL_S) -> list[StepMeasure]:
    """:class:`StepMeasure` of every step of ``record``; levels over ``level_s`` (s),
    held to half a hold."""
    t, q, r, dt = record.t, record.q, record.r, record.dt
    edges = (t[0] - dt, *record.step_times, t[-1])
    out = []
    for prev, t0, nxt in zip(edges, edges[1:], edges[2:], strict=False):
        before, hold = min(level_s, (t0 - prev) / 2), min(level_s, (nxt - t0) / 2)
        q0, r0 = _level(t, q, t0, before), _level(t, r, t0, before)
        q1, r1 = _level(t, q, nxt, hold), _level(t, r, nxt, hold)
        dr = r1 - r0
        require(abs(dr) > 1e-9 * max(abs(r0), abs(r1), 1e-12), "r", f"no step at {t0} s",
                "a commanded rate that changes at every step time", PremiseError)
        m = (t > t0 + 1e-9) & (t <= nxt + 1e-9)
        since = np.r_[0.0, t[m] - t0]
        cumulative = np.r_[0.0, np.cumsum(q[m] - q0) * dt]
        out.append(StepMeasure(t0, dr, q1 - q0, (q1 - q0) / dr, "up" if dr > 0 else "down",
                               float(np.sum(q1 - q[m]) * dt), since, cumulative))
    return out


@dataclass(frozen=True)
class DirectionFit:
    """The steps of one direction pooled.

    ``direction``; ``steps``; ``gain`` (least squares through the origin, 1);
    ``gain_mean``, ``gain_low``, ``gain_high`` (per-step gains: mean and 95 % t interval,
    NaN bounds with one step); ``apparent_delay_s`` (theta + T), ``delay_s`` (theta) and
    ``time_constant_s`` (T), s, by the method of areas (NaN when dq is 0).
    """

    direction: str
    steps: int
    gain: float
    gain_mean: float
    gain_low: float
    gain_high: float
    apparent_delay_s: float
    delay_s: float
    time_constant_s: float


def _areas(steps: Sequence[StepMeasure]) -> tuple[float, float, float]:
    """(theta + T, theta, T) of steps pooled by the method of areas, s."""
    dq = np.array([s.dq for s in steps])
    w = float(dq @ dq)
    if w <= 0:
        return math.nan, math.nan, math.nan
    settle = min(float(s.since[-1]) for s in steps)
    t_ar = float(np.clip(np.array([s.area0 for s in steps]) @ dq / w, 0.0, settle))
    a1 = np.array([np.interp(t_ar, s.since, s.cumulative) for s in steps])
    tau = float(np.clip(math.e * (a1 @ dq) / w, 0.0, t_ar))
    return t_ar, t_ar - tau, tau


def direction_fit(steps: Sequence[StepMeasure], direction: str) -> DirectionFit:
    """:class:`DirectionFit` of the steps of ``direction`` (``"up"`` or ``"down"``);
    all NaN with no such step."""
    mine = [s for s in steps if s.direction == direction]
    if not mine:
        return DirectionFit(direction, 0, *([math.nan] * 7))
    dr, dq = np.array([s.dr for s in mine]), np.array([s.dq for s in mine])
    ci = mean_ci(np.array([s.gain for s in mine]))
    return DirectionFit(direction, len(mine), float(dq @ dr / (dr @ dr)), ci.mean, ci.low,
                        ci.high, *_areas(mine))


def _direction_ok(fit: DirectionFit, th: PremiseThresholds) -> bool:
    lo, hi = th.gain_range
    in_range = fit.steps > 0 and lo <= fit.gain <= hi
    if fit.steps < 2:
        return bool(in_range)
    return bool(in_range and (fit.gain_high - fit.gain_low) / 2 <= th.gain_ci_halfwidth)


def verdict(low: float, high: float, th: PremiseThresholds) -> str:
    """Whether a gain's 95 % interval ``[low, high]`` decides the gate: ``"inside"`` (in
    ``gain_range`` and no wider than ``gain_ci_halfwidth`` allows), ``"outside"``
    (disjoint from the range: the gain is resolved and fails, however wide), else
    ``"unresolved"``."""
    lo, hi = th.gain_range
    if not (math.isfinite(low) and math.isfinite(high)):
        return "unresolved"
    if high < lo or low > hi:
        return "outside"
    if lo <= low and high <= hi and (high - low) / 2 <= th.gain_ci_halfwidth:
        return "inside"
    return "unresolved"


def _level_ok(fit: LevelFit, th: PremiseThresholds) -> bool:
    lo, hi = th.gain_range
    return bool(lo <= fit.gain <= hi and fit.halfwidth <= th.gain_ci_halfwidth)


def actuator_gate(records: ActuatorRecord | Sequence[ActuatorRecord],
                  thresholds: PremiseThresholds | None = None,
                  level_s: float = LEVEL_S, estimator: str = "levels",
                  settle_s: float = SETTLE_S) -> GateResult:
    """Gate 4: dq(L) / dr within ``gain_range`` on both sides of the nominal rate.

    Parameters
    ----------
    records : ActuatorRecord or sequence of them
        One or more runs (e.g. one per seed); their levels (or steps) are pooled.
    thresholds : PremiseThresholds, optional
        ``gain_range`` and ``gain_ci_halfwidth`` are used.
    level_s : float
        The per-step level windows, s (``estimator = "steps"`` and the dead times).
    estimator : {"levels", "steps"}
        ``"levels"``: per side of the nominal rate, the gain regressed on the holds'
        levels, one intercept per record (:mod:`.actuator_levels`); ``"steps"``: per
        step direction, the per-step gains pooled (:func:`direction_fit`).
    settle_s : float
        ``"levels"``: the part of each hold left out of its level, s.

    Returns
    -------
    GateResult
        Named ``actuator``. ``value``: the gain of the side (or direction) farther from
        the range's middle (1); passed when both have a gain in the range whose 95 %
        interval's half width is at most ``gain_ci_halfwidth`` (``"steps"``: with one
        step, the range alone). ``detail``: ``estimator``; per step direction the
        :class:`DirectionFit` fields and ``passed`` (``"up"``, ``"down"``: the dead
        times); with ``"levels"``, ``levels`` per side (the :class:`LevelFit` fields,
        ``passed`` and the interval's :func:`verdict`); ``steps`` (per step t0_s, dr,
        dq, gain, direction).
    """
    th = thresholds or PremiseThresholds()
    require(estimator in ("levels", "steps"), "estimator", estimator,
            "'levels' or 'steps'", PremiseError)
    recs = [records] if isinstance(records, ActuatorRecord) else list(records)
    require(len(recs) >= 1, "records", 0, "at least one record", PremiseError)
    steps = [s for rec in recs for s in step_measures(rec, level_s)]
    fits = {d: direction_fit(steps, d) for d in ("up", "down")}
    ok = {d: _direction_ok(f, th) for d, f in fits.items()}
    detail: dict = {"estimator": estimator,
                    **{d: {**asdict(f), "passed": ok[d]} for d, f in fits.items()}}
    gains = {d: f.gain for d, f in fits.items()}
    if estimator == "levels":
        levels = [hold_levels(r.t, r.q, r.r, r.step_times, settle_s) for r in recs]
        sides = {s: side_fit(levels, s) for s in SIDES}
        ok = {s: _level_ok(f, th) for s, f in sides.items()}
        detail["levels"] = {s: {**asdict(f), "passed": ok[s],
                                "verdict": verdict(f.gain_low, f.gain_high, th)}
                            for s, f in sides.items()}
        gains = {s: f.gain for s, f in sides.items()}
    mid = sum(th.gain_range) / 2
    worst = max(gains.values(), key=lambda g: abs(g - mid) if math.isfinite(g) else math.inf)
    detail["steps"] = [{"t0_s": s.t0, "dr": s.dr, "dq": s.dq, "gain": s.gain,
                        "direction": s.direction} for s in steps]
    return GateResult("actuator", worst, th.gain_range, all(ok.values()), detail)
