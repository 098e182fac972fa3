"""Space-time fields compared at a chosen resolution: block means and their RMSE.

A 50 m x 1 s Edie cell holds two to five vehicles of a class, so its density and speed
carry counting noise that no macroscopic model can or should explain; a macroscopic model
describes means over a few hundred metres and tens of seconds (detector data for
calibration are commonly aggregated to 30 s to 1 min). :func:`block_means` averages a
(periods, variables, cells) field over blocks of ``periods`` x ``cells`` (NaN skipped),
and :func:`field_rmse` compares two fields at that resolution.

:func:`oscillation` measures what the paper's controllers act on, the oscillation of a
field about its own mean at each place: a pooled sd over space and time also counts the
mean profile along the section (slow at the merge, free upstream), which moves with the
operating point, not with the waves.
"""

from __future__ import annotations

import numpy as np


def block_means(field: np.ndarray, periods: int, cells: int) -> np.ndarray:
    """Means of ``field`` (T, V, N) over blocks of ``periods`` x ``cells``, NaN skipped.

    Incomplete trailing blocks are dropped; a block with no finite value is NaN.

    Returns
    -------
    ndarray (T // periods, V, N // cells)
    """
    if periods < 1 or cells < 1:
        raise ValueError(f"block of {periods} periods x {cells} cells; expected >= 1 each")
    n_t, n_v, n_x = field.shape
    bt, bx = n_t // periods, n_x // cells
    f = np.asarray(field, float)[: bt * periods, :, : bx * cells]
    f = f.reshape(bt, periods, n_v, bx, cells)
    ok = np.isfinite(f)
    count = ok.sum(axis=(1, 4))
    total = np.where(ok, f, 0.0).sum(axis=(1, 4))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def field_rmse(observed: np.ndarray, predicted: np.ndarray, periods: int = 1,
               cells: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """RMSE per variable of two (T, V, N) fields at a block resolution.

    Both fields are block-averaged over the same pairs: a value missing (NaN) in either
    is removed from both first, so the blocks compare like with like.

    Returns
    -------
    rmse : ndarray (V,)
        In the fields' units; NaN for a variable with no finite block pair.
    samples : ndarray (V,)
        Block pairs compared per variable.
    """
    both = np.isfinite(observed) & np.isfinite(predicted)
    a = block_means(np.where(both, observed, np.nan), periods, cells)
    b = block_means(np.where(both, predicted, np.nan), periods, cells)
    ok = np.isfinite(a) & np.isfinite(b)
    sq = np.where(ok, (a - b) ** 2, 0.0).sum(axis=(0, 2))
    n = ok.sum(axis=(0, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.sqrt(sq / np.maximum(n, 1)), np.nan), n


def oscillation(field: np.ndarray, periods: int = 1, cells: int = 1) -> np.ndarray:
    """Root mean square over places of each place's temporal sd, per variable.

    ``field`` (T, V, N) is block-averaged first (:func:`block_means`); at each block column
    the sample sd over time (ddof 1, NaN skipped, at least two blocks) measures the
    oscillation about that place's own mean; the columns are then pooled as an RMS. A
    field steady in time has 0 whatever its profile; ``a(x) + A sin(wt)`` has A / sqrt(2).
    A slow drift within the window (a transient after control starts) counts too.

    Parameters
    ----------
    field : ndarray (T, V, N)
        Periods x variables x places, any unit; NaN where not observed.
    periods, cells : int
        Block size in periods and in places (>= 1).

    Returns
    -------
    ndarray (V,)
        In the field's unit; NaN for a variable with no column of two finite blocks.
    """
    blocks = block_means(field, periods, cells)
    n = np.isfinite(blocks).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(blocks, axis=0) / n
        var = np.nansum((blocks - mean) ** 2, axis=0) / (n - 1)
    var = np.where(n >= 2, var, np.nan)
    used = np.isfinite(var).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(used > 0, np.sqrt(np.nansum(var, axis=1) / used), np.nan)


def _fill_in_time(field: np.ndarray) -> np.ndarray:
    """(T, N) with each column's NaN filled linearly in time (ends held); all-NaN stays."""
    out = np.array(field, float)
    t = np.arange(out.shape[0])
    for j in range(out.shape[1]):
        ok = np.isfinite(out[:, j])
        if ok.any():
            out[:, j] = np.interp(t, t[ok], out[ok, j])
    return out


def _lagged_corr(up: np.ndarray, down: np.ndarray, k: int) -> np.ndarray:
    """Per column, corr(up(t), down(t + k)) over the overlap of (T, P) series (k in
    samples, either sign); NaN where a side is constant there."""
    n = up.shape[0]
    a, b = (up[:n - k], down[k:]) if k >= 0 else (up[-k:], down[:n + k])
    if a.shape[0] < 3:
        return np.full(up.shape[1], np.nan)
    a, b = a - a.mean(axis=0), b - b.mean(axis=0)
    norm = np.sqrt((a * a).sum(axis=0) * (b * b).sum(axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, (a * b).sum(axis=0) / norm, np.nan)


def wave_travel(field: np.ndarray, dt: float, dx: float, gap: int,
                max_lag_s: float) -> dict[str, float]:
    """Which way, and how fast, the fluctuations of a (T, N) field travel.

    For every pair of places ``gap`` cells apart the fluctuations (each place's series,
    NaN filled in time) are cross-correlated at lags k = -K..K; the correlations are
    averaged over the pairs and the lag of the peak (> 0: the downstream place follows)
    is the travel time of ``gap dx``. A peak at the edge of the search (|k| = K: slower
    than ``gap dx / max_lag_s``) or within two samples of 0 (faster than the grid
    resolves) gives no speed. A field f(x - c t) gives c when |c| lies between those.

    Parameters
    ----------
    field : ndarray (T, N)
        Periods x places (e.g. a class speed, m/s); NaN where not observed.
    dt : float
        Period, s.
    dx : float
        Distance between neighbouring places, m.
    gap : int
        Places between the two of a pair (>= 1).
    max_lag_s : float
        Largest lag searched, s (held to half the series).

    Returns
    -------
    dict
        ``lag_s`` (s), ``speed`` (m/s; > 0 downstream; NaN when unresolved), ``peak_corr``
        (pair-averaged correlation at the peak) and ``pairs`` (pairs used).
    """
    f = _fill_in_time(field)
    seen = np.isfinite(f).all(axis=0)
    pairs = [j for j in range(f.shape[1] - gap) if seen[j] and seen[j + gap]]
    max_lag = min(max(1, round(max_lag_s / dt)), f.shape[0] // 2)
    lags = np.arange(-max_lag, max_lag + 1)
    up, down = f[:, pairs], f[:, [j + gap for j in pairs]]
    corr = np.array([_lagged_corr(up, down, int(k)) for k in lags]).T.reshape(len(pairs),
                                                                                lags.size)
    used = np.isfinite(corr).any(axis=1)
    if not used.any():
        return {"lag_s": np.nan, "speed": np.nan, "peak_corr": np.nan, "pairs": 0}
    ok = np.isfinite(corr[used])
    mean = np.where(ok, corr[used], 0.0).sum(axis=0) / np.maximum(ok.sum(axis=0), 1)
    mean[~ok.any(axis=0)] = np.nan
    k = int(lags[np.nanargmax(mean)])
    resolved = 2 <= abs(k) < max_lag
    return {"lag_s": k * dt, "speed": gap * dx / (k * dt) if resolved else np.nan,
            "peak_corr": float(np.nanmax(mean)), "pairs": int(used.sum())}
