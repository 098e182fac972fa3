"""Gate 2, the waves: do a class's speed fluctuations travel upstream, at one speed?

Their speed is :func:`arzsumo.evaluation.travel.wave_speed` (the lag of the peak
cross-correlation against the distance between places).

* :func:`wave_gate`: passes when c < 0 (upstream) and the lag is linear in distance
  (r^2 >= ``wave_min_r2`` over at least ``wave_min_pairs`` resolved distances).
* :func:`model_wave_gate`, the model's gate, reported apart: the model's lambda_4 (an
  input) is negative and |lambda_4| lies within ``model_wave_tolerance`` of |c|.

SI units: s, m, m/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from arzsumo.errors import require
from arzsumo.evaluation.travel import DISTANCES_M, MAX_LAG_S, WaveSpeed, wave_speed
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds


def wave_gate(field: np.ndarray, dt: float, dx: float, name: str = "class",
              thresholds: PremiseThresholds | None = None,
              distances_m: Sequence[float] = DISTANCES_M,
              max_lag_s: float = MAX_LAG_S) -> GateResult:
    """Gate 2 for one class: its speed fluctuations travel upstream at one speed.

    Parameters
    ----------
    field, dt, dx, distances_m, max_lag_s
        As :func:`wave_speed` (m/s, s, m, m, s).
    name : str
        The class; the gate is named ``waves[name]``.
    thresholds : PremiseThresholds, optional
        ``wave_min_r2``, ``wave_min_pairs`` and ``wave_min_corr`` are used.

    Returns
    -------
    GateResult
        ``value``: c, m/s; threshold 0 (passed when c < 0, r^2 >= ``wave_min_r2`` and at
        least ``wave_min_pairs`` distances resolved). ``detail``: the :class:`WaveSpeed`
        fields and ``direction`` (``"upstream"``, ``"downstream"`` or ``"unresolved"``).
    """
    th = thresholds or PremiseThresholds()
    w = wave_speed(field, dt, dx, distances_m, max_lag_s, th.wave_min_corr)
    return _wave_result(f"waves[{name}]", w, th)


def _wave_result(name: str, w: WaveSpeed, th: PremiseThresholds) -> GateResult:
    resolved = w.n_used >= th.wave_min_pairs and math.isfinite(w.speed)
    direction = "unresolved" if not resolved else ("upstream" if w.speed < 0
                                                   else "downstream")
    linear = math.isfinite(w.r2) and w.r2 >= th.wave_min_r2
    detail = {"speed_ms": w.speed, "r2": w.r2, "intercept_s": w.intercept_s,
              "distances_m": list(w.distances_m), "lags_s": list(w.lags_s),
              "peak_corr": list(w.peak_corr), "used": list(w.used), "n_used": w.n_used,
              "direction": direction, "linear": linear}
    return GateResult(name, w.speed, 0.0, bool(direction == "upstream" and linear), detail)


def model_wave_gate(lambda_4: float, measured_speed: float, name: str = "class",
                    thresholds: PremiseThresholds | None = None) -> GateResult:
    """The model's gate: |lambda_4| within a tolerance of the measured upstream speed.

    Parameters
    ----------
    lambda_4 : float
        The model's upstream characteristic speed at the operating point, m/s (< 0 in
        the congested regime the paper treats).
    measured_speed : float
        The measured wave speed c (e.g. :attr:`WaveSpeed.speed`), m/s.
    name : str
        The class the speed was measured on; the gate is named ``model_wave[name]``.
    thresholds : PremiseThresholds, optional
        ``model_wave_tolerance`` is used.

    Returns
    -------
    GateResult
        ``value``: |lambda_4| / |c| (NaN when c is not finite or 0); passed when
        lambda_4 < 0, c < 0 and |value - 1| <= the tolerance. ``detail``: ``lambda_4_ms``,
        ``measured_ms``, ``ratio``.
    """
    th = thresholds or PremiseThresholds()
    c = float(measured_speed)
    require(math.isfinite(lambda_4), "lambda_4", lambda_4, "a finite speed, m/s",
            PremiseError)
    ratio = abs(lambda_4) / abs(c) if math.isfinite(c) and c != 0 else math.nan
    ok = lambda_4 < 0 and c < 0 and abs(ratio - 1.0) <= th.model_wave_tolerance
    return GateResult(f"model_wave[{name}]", ratio, th.model_wave_tolerance, bool(ok),
                      {"lambda_4_ms": float(lambda_4), "measured_ms": c, "ratio": ratio})
