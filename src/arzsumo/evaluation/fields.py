"""Space-time fields compared at a chosen resolution: block means, RMSE, oscillation, travel.

A 50 m x 1 s Edie cell holds two to five vehicles of a class, so its values carry counting
noise no macroscopic model should explain: :func:`block_means` averages a field over
blocks (e.g. 100 m x 10 s) before :func:`field_rmse` compares two fields and
:func:`oscillation` measures one about each place's own mean (a pooled sd would also count
the mean profile along the section). docs/outputs.md: ``rmse_blocks``,
``section.speed_oscillation_kmh``, ``section.speed_wave``.
"""

from __future__ import annotations

import numpy as np


def block_means(field: np.ndarray, periods: int, cells: int) -> np.ndarray:
    """Means (T // periods, V, N // cells) of ``field`` (T, V, N) over blocks of ``periods``
    x ``cells``, NaN skipped; incomplete trailing blocks dropped, empty blocks NaN."""
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
    """RMSE per variable (V,; NaN without a finite block pair) of two (T, V, N) fields at
    a block resolution, and the block pairs compared. A value missing (NaN) in either is
    removed from both before the block means, so the blocks compare like with like."""
    both = np.isfinite(observed) & np.isfinite(predicted)
    a = block_means(np.where(both, observed, np.nan), periods, cells)
    b = block_means(np.where(both, predicted, np.nan), periods, cells)
    ok = np.isfinite(a) & np.isfinite(b)
    sq = np.where(ok, (a - b) ** 2, 0.0).sum(axis=(0, 2))
    n = ok.sum(axis=(0, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.sqrt(sq / np.maximum(n, 1)), np.nan), n


def oscillation(field: np.ndarray, periods: int = 1, cells: int = 1) -> np.ndarray:
    """Root mean square over places of each place's temporal sd, per variable (V,).

    ``field`` (T, V, N; any unit, NaN where not observed) is block-averaged first over
    ``periods`` x ``cells`` (:func:`block_means`); each block column's sample sd over time
    (ddof 1, NaN skipped) is pooled as an RMS. A field steady in time has 0 whatever its
    profile, ``a(x) + A sin(wt)`` has A / sqrt(2); a slow drift counts too. NaN for a
    variable with no column of two finite blocks.
    """
    var = temporal_var(block_means(field, periods, cells))
    used = np.isfinite(var).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(used > 0, np.sqrt(np.nansum(var, axis=1) / used), np.nan)


def temporal_var(blocks: np.ndarray) -> np.ndarray:
    """Sample variance over time (axis 0; ddof 1, NaN skipped) of each column of
    ``blocks``; NaN where fewer than two values are finite."""
    n = np.isfinite(blocks).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(blocks, axis=0) / n
        var = np.nansum((blocks - mean) ** 2, axis=0) / (n - 1)
    return np.where(n >= 2, var, np.nan)


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

    ``field``: periods (``dt`` s) x places (``dx`` m apart), e.g. a class speed in m/s,
    NaN where not observed. For every pair of places ``gap`` (>= 1) cells apart the
    series (NaN filled in time) are cross-correlated at lags k = -K..K (K: ``max_lag_s``,
    held to half the series); the lag of the peak of the pair-averaged correlation (> 0:
    the downstream place follows) is the travel time of ``gap dx``. A peak at |k| = K or
    within two samples of 0 gives no speed; f(x - c t) gives c between those.

    Returns ``lag_s`` (s), ``speed`` (m/s; > 0 downstream; NaN when unresolved),
    ``peak_corr`` (at the peak) and ``pairs`` (pairs used).
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
