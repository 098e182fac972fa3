"""How far a run's section is from the stationary state, and how fast a disturbance decays.

The paper judges its laws by the decay of the state's L2 deviation from the equilibrium
(section 5, ``\\label{sec:simulation}``). In SUMO the reference is measured: the
*stationary state* S (4, cells), the time-mean of the Edie cells over the warm-up's last
minutes (the same for every controller of a seed). The relative deviation norm per period is

    e(t) = sqrt( mean over variables k and cells x of ((f_k(t, x) - S_k(x)) / s_k)^2 ),

with s_k the cell-mean of |S_k| (densities and speeds weigh alike; NaN cells left out).
Its 30 s moving mean ē(t) is compared with the *stationary band* theta, the 95th
percentile of ē over the same warm-up minutes; the measures (``decay_time_s``: the last
time ē > theta, ...) are in docs/outputs.md, ``section.deviation``.

Pure numpy: fields in SI (veh/m, m/s), times in s.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

#: moving-mean window of the deviation norm, s: longer than a cell's counting noise
#: (1 s periods), shorter than the section's round trip (about 225 s)
SMOOTH_S = 30.0
#: the stationary band's percentile of the smoothed open-loop norm
BAND_PERCENTILE = 95.0


def _finite_mean(a: np.ndarray, axis: int) -> np.ndarray:
    """Mean of ``a``'s finite values along ``axis``; NaN where there is none."""
    count = np.isfinite(a).sum(axis=axis)
    return np.where(count > 0, np.nansum(a, axis=axis) / np.maximum(count, 1), np.nan)


def stationary_state(fields: np.ndarray) -> np.ndarray:
    """The time-mean (4, cells) of ``fields`` (periods, 4, cells), NaN ignored."""
    return _finite_mean(np.asarray(fields, float), 0)


def deviation_norm(fields: np.ndarray, stationary: np.ndarray) -> np.ndarray:
    """e(t) (periods,) of ``fields`` (periods, 4, cells) from ``stationary`` (4, cells):
    the relative RMS deviation of the module docstring (1)."""
    f, s = np.asarray(fields, float), np.asarray(stationary, float)
    scale = _finite_mean(np.abs(s), 1)  # (4,)
    scale = np.where(scale > 0, scale, np.nan)   # a field with no stationary level is left out
    d = (f - s[None]) / scale[None, :, None]
    ok = np.isfinite(d)
    sq = np.where(ok, d * d, 0.0).sum(axis=(1, 2))
    n = ok.sum(axis=(1, 2))
    return np.where(n > 0, np.sqrt(sq / np.maximum(n, 1)), np.nan)


def moving_mean(e: np.ndarray, periods: int) -> np.ndarray:
    """Trailing mean of ``e`` over ``periods`` samples (fewer at the start)."""
    e = np.asarray(e, float)
    c = np.concatenate([[0.0], np.cumsum(e)])
    i = np.arange(1, e.size + 1)
    lo = np.maximum(i - periods, 0)
    return (c[i] - c[lo]) / (i - lo)


@dataclass(frozen=True)
class Decay:
    """A run's deviation measures (module docstring): s, s, s, 1, bool."""

    decay_time_s: float
    deviation_integral_s: float
    deviation_excess_s: float
    band: float
    decayed: bool

    def as_dict(self) -> dict[str, float | bool]:
        return asdict(self)


def stationary_band(e_open: np.ndarray, period: float, smooth: float = SMOOTH_S) -> float:
    """theta: the BAND_PERCENTILE of the open loop's smoothed norm ``e_open``."""
    sm = moving_mean(e_open, max(1, round(smooth / period)))
    sm = sm[np.isfinite(sm)]      # none in a run too short to have a stationary state
    return float(np.percentile(sm, BAND_PERCENTILE)) if sm.size else float("nan")


def stationary_reference(fields: np.ndarray, period: float) -> tuple[np.ndarray, float]:
    """The stationary state S (4, cells) and band theta of the warm-up's last ``fields``
    (periods, 4, cells; one per period of ``period`` s)."""
    state = stationary_state(fields)
    return state, stationary_band(deviation_norm(fields, state), period)


def decay(t: np.ndarray, e: np.ndarray, band: float, period: float,
          smooth: float = SMOOTH_S) -> Decay:
    """The :class:`Decay` of the norm ``e`` at times ``t`` (s from the start of control,
    one per period of ``period`` s) against the stationary ``band``."""
    t, e = np.asarray(t, float), np.asarray(e, float)
    sm = moving_mean(e, max(1, round(smooth / period)))
    above = sm > band
    ended_above = bool(above[-1]) if above.size else False
    last = float(t[np.flatnonzero(above)[-1]]) if above.any() else 0.0
    return Decay(decay_time_s=float(t[-1]) if ended_above else last,
                 deviation_integral_s=float(np.nansum(e) * period),
                 deviation_excess_s=float(np.nansum(np.maximum(sm - band, 0.0)) * period),
                 band=band, decayed=not ended_above)
