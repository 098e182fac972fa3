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


def _peak_lag(up: np.ndarray, down: np.ndarray, max_lag: int) -> tuple[int, float]:
    """Lag k in [-max_lag, max_lag] (samples) maximising corr(up(t), down(t + k)), and it."""
    n = up.size
    best = (0, -np.inf)
    for k in range(-max_lag, max_lag + 1):
        a, b = (up[:n - k], down[k:]) if k >= 0 else (up[-k:], down[:n + k])
        if a.size > 2 and a.std() > 0 and b.std() > 0:
            c = float(np.corrcoef(a, b)[0, 1])
            if c > best[1]:
                best = (k, c)
    return best


def wave_travel(field: np.ndarray, dt: float, dx: float, gap: int,
                max_lag_s: float) -> dict[str, float]:
    """Which way, and how fast, the fluctuations of a (T, N) field travel.

    For every pair of places ``gap`` cells apart the fluctuations (each place's series
    minus its mean, NaN filled in time) are cross-correlated; the lag of the peak (> 0:
    the downstream place follows) gives a travel time. Returned: the median lag (s), the
    speed ``gap dx`` / median lag (m/s; > 0 downstream, NaN at lag 0), the median peak
    correlation and the pairs used. A field f(x - c t) gives c to the grid's resolution.
    """
    f = _fill_in_time(field)
    seen = np.isfinite(f).all(axis=0)
    f[:, seen] -= f[:, seen].mean(axis=0)
    # at least half of the series overlaps at every lag
    max_lag = min(max(1, round(max_lag_s / dt)), f.shape[0] // 2)
    peaks = [_peak_lag(f[:, j], f[:, j + gap], max_lag) for j in range(f.shape[1] - gap)
             if seen[j] and seen[j + gap]]
    peaks = [p for p in peaks if np.isfinite(p[1])]
    if not peaks:
        return {"lag_s": np.nan, "speed": np.nan, "peak_corr": np.nan, "pairs": 0}
    lag = float(np.median([k for k, _ in peaks])) * dt
    return {"lag_s": lag, "speed": gap * dx / lag if lag else np.nan,
            "peak_corr": float(np.median([c for _, c in peaks])), "pairs": len(peaks)}
