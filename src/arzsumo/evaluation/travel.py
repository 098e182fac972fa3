"""How fast, and which way, a field's fluctuations travel.

On the paper's congested stream (section 2, "Free/congested traffic analysis":
lambda_4 < 0) what the meter does at x = L travels upstream, and so do the speed
fluctuations. :func:`wave_speed` takes, for several distances d between places, the lag of
the peak cross-correlation (:func:`arzsumo.evaluation.fields.wave_travel`) and fits
``lag = a + d / c``: a wave at one speed c gives a line through the origin.

SI units: s, m, m/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arzsumo.errors import ArzsumoError, require
from arzsumo.evaluation.fields import wave_travel


class TravelError(ArzsumoError, ValueError):
    """A field or spacing :func:`wave_speed` cannot read."""

#: distances between the two places of a pair (m) and the largest lag searched (s): 400 m
#: at a congested lambda_4 of -11 km/h takes 130 s; 200 s resolves waves down to 7 km/h
DISTANCES_M, MAX_LAG_S = (100.0, 200.0, 300.0, 400.0), 200.0


@dataclass(frozen=True)
class WaveSpeed:
    """The lag of the peak correlation against the distance between places.

    ``speed``: c of the fit lag = a + d / c, m/s (> 0 downstream; NaN with fewer than
    three resolved distances or a zero slope); ``r2`` of that fit (NaN when the lags do
    not vary); ``intercept_s``: a, s (0 for a pure travelling wave); per distance
    ``distances_m`` d (m), ``lags_s`` (s), ``peak_corr`` and ``used``: in the fit (a peak
    inside the search and correlation >= ``min_corr``).
    """

    speed: float
    r2: float
    intercept_s: float
    distances_m: tuple[float, ...]
    lags_s: tuple[float, ...]
    peak_corr: tuple[float, ...]
    used: tuple[bool, ...]

    @property
    def n_used(self) -> int:
        """Distances in the fit."""
        return int(sum(self.used))


def _line_fit(d: np.ndarray, lag: np.ndarray) -> tuple[float, float, float]:
    """(speed, r^2, intercept) of lag = a + d / c by least squares (NaN if undefined)."""
    if d.size < 3:
        return math.nan, math.nan, math.nan
    slope, intercept = np.polyfit(d, lag, 1)
    ss_tot = float(np.sum((lag - lag.mean()) ** 2))
    ss_res = float(np.sum((lag - (intercept + slope * d)) ** 2))
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else math.nan
    speed = 1.0 / slope if slope != 0 else math.nan
    return float(speed), float(r2), float(intercept)


def wave_speed(field: np.ndarray, dt: float, dx: float,
               distances_m: Sequence[float] = DISTANCES_M, max_lag_s: float = MAX_LAG_S,
               min_corr: float = 0.3) -> WaveSpeed:
    """Speed and direction of the fluctuations of a (T, N) field from lag against distance.

    ``field``, ``dt``, ``dx``, ``max_lag_s`` as in
    :func:`~arzsumo.evaluation.fields.wave_travel`; ``distances_m`` between the places of a
    pair, m, each rounded to whole places (at least one), repeats dropped; ``min_corr``:
    the least peak correlation of a distance used in the fit.
    """
    f = np.asarray(field, float)
    require(f.ndim == 2 and f.shape[0] >= 8 and f.shape[1] >= 2, "field", f.shape,
            "a (periods, places) array with at least 8 periods and 2 places", TravelError)
    require(dt > 0 and dx > 0, "dt, dx", (dt, dx), "a period and a spacing > 0",
            TravelError)
    gaps = sorted({max(1, round(d / dx)) for d in distances_m if round(d / dx) < f.shape[1]})
    edge = min(max(1, round(max_lag_s / dt)), f.shape[0] // 2) * dt
    rows = [wave_travel(f, dt, dx, g, max_lag_s) for g in gaps]
    d = np.array([g * dx for g in gaps])
    lag = np.array([r["lag_s"] for r in rows], float)
    corr = np.array([r["peak_corr"] for r in rows], float)
    used = np.isfinite(lag) & (np.abs(lag) < edge - dt / 2) & (corr >= min_corr)
    speed, r2, intercept = _line_fit(d[used], lag[used])
    return WaveSpeed(speed, r2, intercept, tuple(d.tolist()), tuple(lag.tolist()),
                     tuple(corr.tolist()), tuple(bool(u) for u in used))
