"""What a boundary can reach: the share of a speed field's variance coherent with it.

A boundary actuator (the meter at x = L, the outlet's speed limit) acts on the section
only through a boundary series b(t): the outlet's flow q(L, t), the inlet's flow
q(0, t), the law's input U(t). The part of a cell's speed v(t, x) that *any* linear
time-invariant filter of b can produce is, frequency by frequency, the magnitude-squared
coherence

    C(x, f) = |S_bv(x, f)|^2 / (S_bb(f) S_vv(x, f))        (1, in [0, 1])

times the cell's power S_vv(x, f): C S_vv = |S_bv|^2 / S_bb is the power of the best LTI
prediction of v from b, the rest is what b does not carry. The *coherent share* of the
cell's speed variance in a band of periods is the variance-weighted coherence

    share(x) = sum_{f in band} C(x, f) S_vv(x, f) / sum_{f in band} S_vv(x, f),

and along the section

    share_section = sum_x sum_f C S_vv / sum_x sum_f S_vv   (the headline: the share of
                                                             the section's variance),
    share_plain   = mean over x of share(x)                  (each place counted alike).

A field ``a(x) (h * b)(t - tau(x)) + n(t, x)`` with noise n independent of b has, in a
band, share = signal power / (signal + noise power): it depends neither on the scale a(x)
nor on the filter h where |H| is flat, nor on the delay tau (but see *lags* below).

Estimator (Welch, :func:`scipy.signal.csd`)
-------------------------------------------
* Hann window, 50 % overlap, each segment linearly detrended; one-sided densities
  (S_vv in (m/s)^2 s, S_bb in b's unit^2 s). Frequencies f = k / segment_s (Hz); a band
  (shortest, longest period) holds the bins with 1/longest <= f <= 1/shortest (both ends
  in, as :func:`arzsumo.evaluation.waves.band_power`: a bin at exactly 60 s counts in
  both default bands), and ``bins`` says how many: a period longer than the segment is
  not resolved at all.
* **Segment length** ``segment_s``: default the shorter of :data:`MAX_SEGMENT_S` (1200 s:
  bins at 1/1200 and 1/600 Hz, so the 10 min end of the stop-and-go band is resolved)
  and half the shortest record, in an even number of samples (three 50 %-overlapping
  segments per record). The trade-off: a longer segment resolves longer periods and finer
  frequencies, but leaves fewer segments to average, and the estimate's bias (the floor
  below) and variance grow as 1 / segments. A run's 450 s control window at 1 s gives
  224 s segments: bins at periods 224, 112, 75 s in the 1-10 min band, 56 to 20.4 s
  (8 bins) in the 20 s-1 min band; periods of 4-10 min are not measured by such records.
* **Records pooled over runs**: ``v`` and ``b`` may be lists (one record per run, e.g.
  paired seeds of one stream and controller). The spectra are averaged over every
  segment of every run (each run weighted by its segment count), which is Welch's
  average with more segments; runs of one condition are taken as realisations of one
  stationary process. One 450 s record alone has a floor near 0.35 (below): pool seeds.
* **Lags** ``lag_s``: the true coherence does not depend on a delay between b and v, but
  Welch's estimate does: a delay that is a sizeable part of the segment leaves each
  segment's pair partly unaligned and pulls the estimate down (for Hann by about the
  square of the window's autocorrelation at the delay: -15 % at 7.5 % of the segment).
  Pass each cell's travel time from the boundary (:func:`travel_lags`: (x - x_b) / c,
  e.g. (L - x) / |lambda_4| from the outlet for waves travelling upstream); the pair
  (b(t), v(t + lag)) is then compared over the records' overlap.
* **The bias floor.** For b independent of v the estimate is not 0: with n independent
  (Gaussian) segments, C-hat ~ Beta(1, n - 1) whatever v's spectrum, so E[C-hat] = 1 / n
  and so is the expected share (the weights S_vv come from v alone). For overlapping
  windows n is Welch's equivalent number of independent segments,
  n_eff = K / (1 + 2 sum_{m=1}^{K-1} (1 - m/K) rho(m)^2) for K segments with rho(m) the
  window's normalised overlap correlation at m steps (Hann at 50 %: rho(1) = 1/6), summed
  over runs. ``floor`` = 1 / n_eff per cell, weighted like the share along x; a share at
  or below the floor is no evidence of coherence. At the lowest bin (the period of the
  segment) each segment's linear detrend takes a share of the segment's own variance and
  the floor there is about 25 % above 1 / n_eff (measured: 0.0216 for 0.0173 on 20
  records of 450 s), so a band holding that bin has a floor a few % to 10 % higher.
  :func:`surrogate_floor` measures the floor, that bin included, with Gaussian surrogates
  of b (its smoothed spectrum kept, any relation to v lost; :func:`spectral_surrogate`).
  The share beyond the floor, ``(share - floor) / (1 - floor)``, is unbiased for b
  independent of v and close to the true share above it (a coherence gamma^2 is read as
  about gamma^2 + (1 - gamma^2)^2 / n_eff).
* A boundary series held constant over a run (an ETC that never updates U) carries no
  power: its coherent power is 0 there (``boundary_power`` shows it), not undefined.

Inputs are complete series: fill a cell's empty periods (NaN speeds) in time first, e.g.
linearly; a non-finite value is refused. SI: t and periods s, f Hz, x m, v m/s, b veh/s
(any unit: the share is dimensionless). Pure numpy/scipy/pandas: no SUMO, no files.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike
from scipy.ndimage import uniform_filter1d
from scipy.signal import csd, get_window, welch

from arzsumo.errors import ArzsumoError, require
from arzsumo.evaluation.waves import SHORT_WAVES_S, STOP_AND_GO_S

#: the bands of periods (shortest, longest; s): the short waves and the stop-and-go band
BANDS_S: dict[str, tuple[float, float]] = {"short_waves": SHORT_WAVES_S,
                                           "stop_and_go": STOP_AND_GO_S}
#: the longest default Welch segment, s (resolves a 10 min period at its second bin)
MAX_SEGMENT_S = 1200.0
#: Welch's window and overlap (share of a segment)
WINDOW, OVERLAP = "hann", 0.5
#: fewest samples of a segment
MIN_SEGMENT = 8
#: a record whose detrended variance is below this share of its mean square is held
HELD_RTOL = 1e-20


class CoherenceError(ArzsumoError, ValueError):
    """Series the coherence measure cannot use (shape, non-finite values, too short)."""


def _require(condition: bool, field: str, value: object, allowed: str) -> None:
    require(bool(condition), field, value, allowed, CoherenceError)


class _Text(str):
    """A value described in words, shown unquoted in a message."""

    def __repr__(self) -> str:
        return str(self)


def _shape(a: np.ndarray) -> str:
    return _Text(f"an array of shape {a.shape}")


def _non_finite(a: np.ndarray) -> str:
    return _Text(f"{(~np.isfinite(a)).sum()} non-finite values")


def _as_runs(v: ArrayLike | Sequence[ArrayLike], b: ArrayLike | Sequence[ArrayLike]
             ) -> list[tuple[np.ndarray, np.ndarray]]:
    """``(v (T, N), b (T,))`` per run, checked; one array each or one list each."""
    one = isinstance(v, np.ndarray) or (isinstance(v, Sequence) and len(v) > 0
                                       and np.ndim(v[0]) == 1)
    vs = [v] if one else list(v)                                   # type: ignore[arg-type]
    bs = [b] if one else list(b)                                   # type: ignore[arg-type]
    _require(len(vs) == len(bs) and vs, "b", _Text(f"{len(bs)} runs"),
             f"one boundary series per speed field ({len(vs)} runs)")
    runs, n_x = [], None
    for r, (vr, br) in enumerate(zip(vs, bs, strict=True)):
        vr, br = np.asarray(vr, float), np.asarray(br, float)
        _require(vr.ndim == 2 and vr.shape[1] > 0, f"v[{r}]", _shape(vr),
                 "a speed field (T periods, N cells) with N >= 1")
        _require(n_x is None or vr.shape[1] == n_x, f"v[{r}]", _shape(vr),
                 f"the same {n_x} cells in every run")
        _require(br.shape == (vr.shape[0],), f"b[{r}]", _shape(br),
                 f"a series of the field's {vr.shape[0]} periods")
        _require(np.isfinite(vr).all(), f"v[{r}]", _non_finite(vr),
                 "finite speeds (fill empty cells in time first)")
        _require(np.isfinite(br).all(), f"b[{r}]", _non_finite(br), "a finite series")
        n_x = vr.shape[1]
        runs.append((vr, br))
    return runs


def _lag_samples(lag_s: ArrayLike, n_x: int, dt: float) -> np.ndarray:
    lag = np.asarray(lag_s, float)
    _require(lag.ndim == 0 or lag.shape == (n_x,), "lag_s", _shape(lag),
             f"one lag (s) or one per cell ({n_x})")
    _require(np.isfinite(lag).all(), "lag_s", lag.tolist(), "finite lags, s")
    return np.rint(np.broadcast_to(lag, (n_x,)) / dt).astype(int)


def _check_bands(bands: Mapping[str, tuple[float, float]]) -> np.ndarray:
    _require(len(bands) > 0, "bands", dict(bands), "at least one band")
    arr = np.array([tuple(map(float, p)) for p in bands.values()], float).reshape(-1, 2)
    _require(np.isfinite(arr).all() and (arr[:, 0] > 0).all() and (arr[:, 1] > arr[:, 0]).all(),
             "bands", dict(bands), "(shortest, longest) periods in s with 0 < shortest < longest")
    return arr


def segment_samples(records: Sequence[int], dt: float, segment_s: float | None = None) -> int:
    """Samples of a Welch segment: ``segment_s / dt`` rounded, or by default the shorter
    of :data:`MAX_SEGMENT_S` and half the shortest of ``records`` (samples each), made
    even (so that three 50 %-overlapping segments fill twice its length)."""
    _require(np.isfinite(dt) and dt > 0, "dt", dt, "a period > 0, s")
    shortest = min(records)
    seg = min(MAX_SEGMENT_S, shortest * dt / 2) if segment_s is None else segment_s
    n = round(seg / dt) if segment_s is not None else 2 * int(seg / dt / 2)
    _require(MIN_SEGMENT <= n <= shortest, "segment_s", seg,
             f"a segment of {MIN_SEGMENT} to {shortest} samples of {dt} s (the shortest record)")
    return n


def effective_segments(samples: int, nperseg: int) -> float:
    """Welch's equivalent number of independent segments of a record of ``samples``
    (Hann window, :data:`OVERLAP`): K / (1 + 2 sum_m (1 - m/K) rho(m)^2); 0 if K = 0."""
    step = nperseg - int(nperseg * OVERLAP)
    k = (samples - nperseg) // step + 1 if samples >= nperseg else 0
    if k < 1:
        return 0.0
    w = get_window(WINDOW, nperseg)
    m = np.arange(1, k)
    rho = np.array([w[: nperseg - j * step] @ w[j * step:] if j * step < nperseg else 0.0
                    for j in m]) / (w @ w)
    return float(k / (1.0 + 2.0 * np.sum((1.0 - m / k) * rho ** 2)))


def _spectra(b: np.ndarray, v: np.ndarray, nperseg: int, dt: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """f (F,), S_bb (F,), S_vv (N, F), S_bv (N, F) of one aligned record (b (T,),
    v (T, N)); a held b (detrended variance ~ 0) is taken as exactly 0."""
    t = np.arange(b.size)
    resid = b - np.polyval(np.polyfit(t, b, 1), t)
    if resid @ resid <= HELD_RTOL * max(b @ b, np.finfo(float).tiny):
        b = np.zeros_like(b)
    opts = {"fs": 1.0 / dt, "window": WINDOW, "nperseg": nperseg,
            "noverlap": int(nperseg * OVERLAP), "detrend": "linear"}
    f, s_bb = welch(b, **opts)
    _, s_vv = welch(v.T, **opts)
    _, s_bv = csd(b[None, :], v.T, **opts)
    return f, s_bb, s_vv, s_bv


def _pooled(runs: list[tuple[np.ndarray, np.ndarray]], lags: np.ndarray, nperseg: int,
            dt: float) -> dict[str, np.ndarray]:
    """Segment-weighted spectra over runs per cell, each cell's pair (b(t), v(t + lag))."""
    n_x, acc = lags.size, {}
    for v, b in runs:
        for k in np.unique(lags):
            cells = np.flatnonzero(lags == k)
            vk, bk = (v[k:, cells], b[: b.size - k]) if k >= 0 else (v[:k, cells], b[-k:])
            _require(bk.size >= nperseg, "lag_s", float(k * dt),
                     f"lags leaving a segment of {nperseg * dt} s of a {b.size * dt} s record")
            step = nperseg - int(nperseg * OVERLAP)
            weight = (bk.size - nperseg) // step + 1
            f, s_bb, s_vv, s_bv = _spectra(bk, vk, nperseg, dt)
            if not acc:
                acc = {"f": f, "bb": np.zeros((n_x, f.size)), "vv": np.zeros((n_x, f.size)),
                       "bv": np.zeros((n_x, f.size), complex), "k": np.zeros(n_x),
                       "n_eff": np.zeros(n_x)}
            acc["bb"][cells] += weight * s_bb
            acc["vv"][cells] += weight * s_vv
            acc["bv"][cells] += weight * s_bv
            acc["k"][cells] += weight
            acc["n_eff"][cells] += effective_segments(bk.size, nperseg)
    for key in ("bb", "vv", "bv"):
        acc[key] /= acc["k"][:, None]
    return acc


@dataclass(frozen=True)
class CoherentShare:
    """The coherent share of a speed field with one boundary series (module docstring).

    Attributes
    ----------
    band_names : tuple of str
        B bands; ``band_s`` (B, 2) their (shortest, longest) periods, s.
    x : ndarray (N,)
        Cells, m.
    f : ndarray (F,)
        Welch frequencies, Hz (0 first).
    coherence : ndarray (N, F)
        Magnitude-squared coherence of each cell with b, 1 (0 where b or v is silent).
    psd : ndarray (N, F)
        Each cell's speed density S_vv, (m/s)^2 s.
    share : ndarray (B, N)
        Coherent share of each cell's band variance, 1 (NaN where v has no band power).
    power : ndarray (B, N)
        Each cell's speed variance in the band, (m/s)^2.
    boundary_power : ndarray (B,)
        b's variance in the band (mean over the cells' alignments), b's unit^2.
    bins : ndarray of int (B,)
        Welch bins inside each band (0: the band is not resolved, its shares NaN).
    segments : ndarray (N,)
        Equivalent independent segments n_eff per cell, summed over runs.
    segment_s : float
        Welch segment, s.
    runs : int
        Records pooled.
    """

    band_names: tuple[str, ...]
    band_s: np.ndarray
    x: np.ndarray
    f: np.ndarray
    coherence: np.ndarray
    psd: np.ndarray
    share: np.ndarray
    power: np.ndarray
    boundary_power: np.ndarray
    bins: np.ndarray
    segments: np.ndarray
    segment_s: float
    runs: int

    def __post_init__(self) -> None:
        n_b, n_x, n_f = len(self.band_names), self.x.size, self.f.size
        for name, shape in (("band_s", (n_b, 2)), ("x", (n_x,)), ("coherence", (n_x, n_f)),
                            ("psd", (n_x, n_f)), ("share", (n_b, n_x)), ("power", (n_b, n_x)),
                            ("boundary_power", (n_b,)), ("bins", (n_b,)),
                            ("segments", (n_x,))):
            got = np.shape(getattr(self, name))
            _require(got == shape, name, f"shape {got}", f"shape {shape}")
        s = self.share[np.isfinite(self.share)]
        _require(((s >= 0) & (s <= 1 + 1e-9)).all(), "share", s.tolist(), "shares in [0, 1]")
        _require((self.segments > 0).all(), "segments", self.segments.tolist(),
                 "at least one segment per cell")
        _require(self.runs >= 1, "runs", self.runs, "at least one record")

    @property
    def floor(self) -> np.ndarray:
        """The bias floor per cell, 1 / n_eff (N,): the share expected of an independent b."""
        return 1.0 / self.segments

    def _weighted(self, values: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore"):
            num = np.nansum(values * self.power, axis=1)
            den = np.where(np.isfinite(values), self.power, 0.0).sum(axis=1)
            return np.where((den > 0) & (self.bins > 0), num / den, np.nan)

    @property
    def share_section(self) -> np.ndarray:
        """The headline (B,): the share of the section's band variance, cells weighted by
        their band power."""
        return self._weighted(self.share)

    @property
    def share_plain(self) -> np.ndarray:
        """The mean over cells of each cell's share (B,), each place alike."""
        out = np.full(len(self.band_names), np.nan)
        for i, row in enumerate(self.share):
            if self.bins[i] > 0 and np.isfinite(row).any():
                out[i] = np.nanmean(row)
        return out

    @property
    def floor_section(self) -> np.ndarray:
        """The floor (B,) weighted along x like :attr:`share_section`."""
        floor = np.where(np.isfinite(self.share), self.floor[None, :], np.nan)
        return self._weighted(floor)

    @property
    def beyond_floor(self) -> np.ndarray:
        """(share_section - floor_section) / (1 - floor_section) (B,): about 0, either
        sign, for an independent b; NaN where b is held (no power in the band)."""
        beyond = (self.share_section - self.floor_section) / (1.0 - self.floor_section)
        return np.where(self.boundary_power > 0, beyond, np.nan)

    def table(self) -> pd.DataFrame:
        """One row per band: ``band``, ``period_short_s``, ``period_long_s``, ``share``
        (the headline), ``share_plain``, ``floor``, ``beyond_floor``, ``bins``,
        ``segments`` (mean n_eff), ``boundary_power``, ``runs``, ``segment_s``."""
        return pd.DataFrame({
            "band": list(self.band_names), "period_short_s": self.band_s[:, 0],
            "period_long_s": self.band_s[:, 1], "share": self.share_section,
            "share_plain": self.share_plain, "floor": self.floor_section,
            "beyond_floor": self.beyond_floor, "bins": self.bins,
            "segments": float(self.segments.mean()), "boundary_power": self.boundary_power,
            "runs": self.runs, "segment_s": self.segment_s})

    def cells(self) -> pd.DataFrame:
        """One row per band and cell: ``band``, ``x_m``, ``share``, ``power``, ``floor``."""
        n_b, n_x = self.share.shape
        return pd.DataFrame({"band": np.repeat(self.band_names, n_x),
                             "x_m": np.tile(self.x, n_b), "share": self.share.ravel(),
                             "power": self.power.ravel(), "floor": np.tile(self.floor, n_b)})


def _band_sums(acc: dict[str, np.ndarray], band_s: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """coherence (N, F); share, power (B, N); boundary power, bins (B,)."""
    f, s_bb, s_vv, s_bv = acc["f"], acc["bb"], acc["vv"], acc["bv"]
    df = f[1] - f[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        coherent = np.where(s_bb > 0, np.abs(s_bv) ** 2 / s_bb, 0.0)   # C S_vv
        coherence = np.where(s_vv > 0, np.minimum(coherent / s_vv, 1.0), 0.0)
    inside = (f[None, :] >= 1.0 / band_s[:, 1:2]) & (f[None, :] <= 1.0 / band_s[:, 0:1])
    inside &= f[None, :] > 0
    power = (s_vv[None] * inside[:, None]).sum(axis=2) * df
    num = (np.minimum(coherent, s_vv)[None] * inside[:, None]).sum(axis=2) * df
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(power > 0, num / power, np.nan)
    boundary = (s_bb.mean(axis=0)[None] * inside).sum(axis=1) * df
    return coherence, share, power, boundary, inside.sum(axis=1)


def coherent_share(v: ArrayLike | Sequence[ArrayLike], b: ArrayLike | Sequence[ArrayLike],
                   dt: float, x: ArrayLike, *, lag_s: ArrayLike = 0.0,
                   bands: Mapping[str, tuple[float, float]] = BANDS_S,
                   segment_s: float | None = None) -> CoherentShare:
    """coherent_share(v, b, dt, x, lag_s=0.0, bands=BANDS_S, segment_s=None)

    The share of each cell's speed variance per band that is coherent with ``b``.

    Parameters
    ----------
    v : ndarray (T, N), or a list of them (one per run, the same N cells)
        Speed field on a uniform time grid, m/s; finite.
    b : ndarray (T,), or a list of them (one per run)
        Boundary series on the same grid (q(0, t), q(L, t) in veh/s, U(t), ...).
    dt : float
        Sampling period, s.
    x : ndarray (N,)
        Cell positions, m.
    lag_s : float or ndarray (N,), optional
        Travel time from the boundary to each cell, s (:func:`travel_lags`); the pair
        (b(t), v(t + lag)) is compared. 0: no alignment.
    bands : mapping, optional
        Name -> (shortest, longest) period, s. Default :data:`BANDS_S`.
    segment_s : float, optional
        Welch segment, s; default min(:data:`MAX_SEGMENT_S`, half the shortest record).

    Returns
    -------
    CoherentShare
    """
    runs = _as_runs(v, b)
    xs = np.asarray(x, float)
    n_x = runs[0][0].shape[1]
    _require(xs.shape == (n_x,) and np.isfinite(xs).all(), "x", _shape(xs),
             f"{n_x} finite cell positions, m")
    band_s = _check_bands(bands)
    nperseg = segment_samples([bb.size for _, bb in runs], dt, segment_s)
    acc = _pooled(runs, _lag_samples(lag_s, n_x, dt), nperseg, dt)
    coherence, share, power, boundary, bins = _band_sums(acc, band_s)
    share[bins == 0] = np.nan
    return CoherentShare(tuple(bands), band_s, xs, acc["f"], coherence, acc["vv"], share,
                         power, boundary, bins, acc["n_eff"], nperseg * dt, len(runs))


def travel_lags(x: ArrayLike, boundary_x: float, speed: float) -> np.ndarray:
    """Travel time (s) of a wave of ``speed`` (m/s; < 0 upstream) from ``boundary_x`` (m)
    to each cell ``x`` (m): (x - boundary_x) / speed; e.g. from the outlet x = L at the
    congested lambda_4 < 0, (L - x) / |lambda_4|."""
    _require(np.isfinite(speed) and speed != 0, "speed", speed, "a non-zero wave speed, m/s")
    return (np.asarray(x, float) - boundary_x) / speed


@dataclass(frozen=True)
class BoundaryShares:
    """:class:`CoherentShare` of one field with several boundary series, by name (e.g.
    ``q0``, ``qL``, ``U``); the same cells and bands in each."""

    results: Mapping[str, CoherentShare]

    def __post_init__(self) -> None:
        _require(len(self.results) > 0, "results", dict(self.results), "at least one boundary")
        first = next(iter(self.results.values()))
        for name, r in self.results.items():
            _require(r.band_names == first.band_names and np.array_equal(r.x, first.x),
                     f"results[{name!r}]", "other cells or bands", "the same cells and bands")

    def table(self) -> pd.DataFrame:
        """:meth:`CoherentShare.table` of each boundary, tidy, with a ``boundary`` column."""
        return pd.concat([r.table().assign(boundary=name) for name, r in self.results.items()],
                         ignore_index=True).set_index(["boundary", "band"]).reset_index()

    def cells(self) -> pd.DataFrame:
        """:meth:`CoherentShare.cells` of each boundary, with a ``boundary`` column."""
        return pd.concat([r.cells().assign(boundary=name) for name, r in self.results.items()],
                         ignore_index=True).set_index(["boundary", "band"]).reset_index()


def boundary_shares(v: ArrayLike | Sequence[ArrayLike],
                    boundaries: Mapping[str, ArrayLike | Sequence[ArrayLike]], dt: float,
                    x: ArrayLike, *, lags: Mapping[str, ArrayLike] | None = None,
                    bands: Mapping[str, tuple[float, float]] = BANDS_S,
                    segment_s: float | None = None) -> BoundaryShares:
    """:func:`coherent_share` of ``v`` with each series of ``boundaries`` (name -> b, as
    ``b`` there), each aligned by ``lags[name]`` (s; missing: 0)."""
    lags = dict(lags or {})
    _require(set(lags) <= set(boundaries), "lags", sorted(lags),
             f"lags of named boundaries {sorted(boundaries)}")
    return BoundaryShares({name: coherent_share(v, b, dt, x, lag_s=lags.get(name, 0.0),
                                                bands=bands, segment_s=segment_s)
                           for name, b in boundaries.items()})


def spectral_surrogate(b: ArrayLike, rng: np.random.Generator, smooth_bins: int = 1
                       ) -> np.ndarray:
    """A Gaussian series with the mean of ``b`` (T,) and, in expectation, its spectrum:
    the Fourier amplitudes of ``b`` smoothed over ``smooth_bins`` bins either side, times
    complex Gaussian numbers. Smoothed, so that it carries neither b's phases nor its
    bin-by-bin amplitudes: a phase-randomised copy keeps those amplitudes, and against a
    field coherent with b it reads about 1.5 times the floor."""
    arr = np.asarray(b, float)
    spec = np.fft.rfft(arr - arr.mean())
    width = 2 * max(int(smooth_bins), 0) + 1
    power = uniform_filter1d(np.abs(spec) ** 2, width, mode="nearest")
    z = (rng.standard_normal(spec.size) + 1j * rng.standard_normal(spec.size)) / np.sqrt(2)
    z[0] = 0.0
    if arr.size % 2 == 0:
        z[-1] = rng.standard_normal()                          # the Nyquist bin stays real
    return np.fft.irfft(np.sqrt(power) * z, n=arr.size) + arr.mean()


def surrogate_floor(v: ArrayLike | Sequence[ArrayLike], b: ArrayLike | Sequence[ArrayLike],
                    dt: float, x: ArrayLike, *, surrogates: int = 20, seed: int = 0,
                    **options) -> np.ndarray:
    """The headline share (surrogates, B) of ``v`` with surrogates of ``b``
    (:func:`spectral_surrogate`, each run's series redrawn, its amplitudes smoothed over
    two Welch bins either side; ``options`` as :func:`coherent_share`): the estimator's
    floor measured, with its spread."""
    _require(surrogates >= 1, "surrogates", surrogates, "at least 1")
    runs = _as_runs(v, b)
    nperseg = segment_samples([br.size for _, br in runs], dt, options.get("segment_s"))
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(surrogates):
        fake = [spectral_surrogate(br, rng, 2 * br.size // nperseg) for _, br in runs]
        out.append(coherent_share([vr for vr, _ in runs], fake, dt, x,
                                  **options).share_section)
    return np.array(out)
