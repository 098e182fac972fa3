"""Wave measures of a speed field: oscillation, stop-and-go band power, growth upstream.

The section's per-vehicle speed sd pools every sample, so in SUMO's sublane model it
mostly measures the speed gap between *lateral files* (vehicles riding side by side in
the wide lane), not waves. The measures here look at what waves are: the fluctuation in
time of block-mean speeds at each place (blocks of e.g. 100 m x 10 s,
:func:`arzsumo.evaluation.fields.block_means`):

* :func:`temporal_sd`: each place's sd over time; its RMS over places is
  :func:`arzsumo.evaluation.fields.oscillation`;
* :func:`band_power`: the share of that variance in the stop-and-go band (periods of 1 to
  10 min, :data:`STOP_AND_GO_S`), from a Hann-windowed periodogram of each place's
  linearly detrended series;
* :func:`peak_period`: the period of the places' mean periodogram's peak, and the power
  in the short waves' band (20 s to 1 min, :data:`SHORT_WAVES_S`);
* :func:`growth_upstream`: the log-linear slope of the amplitude (the temporal sd) against
  the distance upstream from x = L; > 0 when waves grow as they travel upstream;
* :func:`file_boundaries` and :func:`snapshot_blocks`: the lateral files of a class, found
  from a histogram of lateral offsets with empty gaps between files, and the block
  speeds of the vehicles of one file, so that every measure can be taken per file.

Pure numpy/scipy, SI units (m, s, m/s); :func:`wave_measures` bundles them.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from scipy.signal import periodogram

#: the stop-and-go band: periods from 1 to 10 min, s
STOP_AND_GO_S = (60.0, 600.0)
#: the short waves' band: periods from 20 s to 1 min, s (resolved on blocks of <= 10 s);
#: where the IDM stream's stop-and-go has most of its power (peaks at 43-64 s)
SHORT_WAVES_S = (20.0, 60.0)
#: fewest blocks of a place's series for a spectrum; fewest places for a growth slope
MIN_BLOCKS, MIN_PLACES = 8, 3


def temporal_sd(blocks: np.ndarray) -> np.ndarray:
    """Each place's sample sd over time (ddof 1, NaN skipped).

    Parameters
    ----------
    blocks : ndarray (T, N)
        Block-mean speeds, m/s; NaN where a block holds no vehicle.

    Returns
    -------
    ndarray (N,)
        m/s; NaN at a place with fewer than two finite blocks.
    """
    b = np.asarray(blocks, float)
    n = np.isfinite(b).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(b, axis=0) / n
        var = np.nansum((b - mean) ** 2, axis=0) / (n - 1)
    return np.where(n >= 2, np.sqrt(np.maximum(var, 0.0)), np.nan)


def rms(values: np.ndarray) -> float:
    """Root mean square of the finite values (NaN when none): e.g. the RMS over places of
    :func:`temporal_sd`, :func:`arzsumo.evaluation.fields.oscillation` of one variable."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v * v))) if v.size else float("nan")


def _filled(series: np.ndarray, min_coverage: float) -> np.ndarray | None:
    """``series`` with its NaN filled linearly in time (ends held), or None when fewer
    than ``min_coverage`` of it (or fewer than MIN_BLOCKS values) are finite."""
    ok = np.isfinite(series)
    if ok.sum() < max(MIN_BLOCKS, min_coverage * series.size):
        return None
    t = np.arange(series.size)
    return np.interp(t, t[ok], series[ok])


@dataclass(frozen=True)
class PlaceSpectra:
    """The one-sided periodogram densities ``psd`` (P, F; (m/s)^2 s) of each place's
    series used, at frequencies ``f`` (F,; Hz): what :func:`band_power`,
    :func:`mean_periodogram` and :func:`peak_period` read. P may be 0."""

    f: np.ndarray
    psd: np.ndarray

    def band(self, band: tuple[float, float]) -> dict[str, float]:
        """:func:`band_power`'s result for ``band`` (shortest, longest period, s)."""
        if not self.psd.shape[0]:
            return {"band_power": np.nan, "total_variance": np.nan, "band_share": np.nan,
                    "places": 0}
        df = self.f[1] - self.f[0]
        inside = (self.f >= 1.0 / band[1]) & (self.f <= 1.0 / band[0])
        b = float(self.psd[:, inside].sum(axis=1).mean() * df)
        tot = float(self.psd[:, 1:].sum(axis=1).mean() * df)
        return {"band_power": b, "total_variance": tot,
                "band_share": b / tot if tot > 0 else np.nan,
                "places": int(self.psd.shape[0])}

    def mean(self) -> tuple[np.ndarray, np.ndarray]:
        """:func:`mean_periodogram`'s result."""
        if not self.psd.shape[0] or self.f.size < 2:
            return np.zeros(0), np.zeros(0)
        return 1.0 / self.f[1:], self.psd[:, 1:].mean(axis=0)

    def peak_period(self) -> float:
        """:func:`peak_period`'s result."""
        periods, mean = self.mean()
        if not np.any(mean > 0):
            return float("nan")
        return float(periods[int(np.argmax(mean))])


def place_spectra(blocks: np.ndarray, dt: float, min_coverage: float = 0.75
                  ) -> PlaceSpectra:
    """Each place's series of ``blocks`` (T, N; block duration ``dt`` s) with at least
    ``min_coverage`` finite blocks, NaN filled in time, linearly detrended and
    Hann-windowed, as its periodogram."""
    f, psds = np.zeros(0), []
    for series in np.asarray(blocks, float).T:
        x = _filled(series, min_coverage)
        if x is None:
            continue
        f, psd = periodogram(x, fs=1.0 / dt, window="hann", detrend="linear")
        psds.append(psd)
    return PlaceSpectra(f, np.array(psds).reshape(len(psds), f.size))


def band_power(blocks: np.ndarray, dt: float, band: tuple[float, float] = STOP_AND_GO_S,
               min_coverage: float = 0.75) -> dict[str, float]:
    """Spectral power of each place's block series in a band of periods, averaged over places.

    Each place's series (NaN filled linearly in time; a place with less than
    ``min_coverage`` finite blocks is skipped) is detrended linearly and Hann-windowed;
    its one-sided periodogram density integrated over the band's frequencies is the band
    power, over all frequencies above 0 the total variance. A sine of amplitude A and a
    period inside the band gives A^2 / 2 in the band and a share near 1. Periods longer
    than the series are not resolved (their power shows up at its lowest frequencies).

    Parameters
    ----------
    blocks : ndarray (T, N)
        Block-mean speeds, m/s.
    dt : float
        Block duration, s.
    band : (float, float)
        Shortest and longest period of the band, s.
    min_coverage : float
        Least share of finite blocks of a place used.

    Returns
    -------
    dict
        ``band_power`` and ``total_variance`` (means over the places used, (m/s)^2),
        ``band_share`` (their ratio, 1) and ``places`` (places used); NaN without any.
    """
    return place_spectra(blocks, dt, min_coverage).band(band)


def mean_periodogram(blocks: np.ndarray, dt: float, min_coverage: float = 0.75
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Periods (s, longest first; frequency 0 left out) and the places' mean one-sided
    periodogram density ((m/s)^2 s) of ``blocks`` (T, N; as :func:`band_power`); both
    empty without a place used."""
    return place_spectra(blocks, dt, min_coverage).mean()


def peak_period(blocks: np.ndarray, dt: float, min_coverage: float = 0.75) -> float:
    """The period (s) at which the places' mean periodogram of ``blocks`` (T, N; as
    :func:`band_power`) is largest, frequency 0 excluded: the waves' dominant period.
    NaN without a place, a resolved frequency or any power (a field standing still)."""
    return place_spectra(blocks, dt, min_coverage).peak_period()


def growth_upstream(x: np.ndarray, amplitude: np.ndarray, length: float) -> float:
    """Log-linear slope of ``amplitude`` against the distance upstream from x = ``length``.

    Fits ``log a = c + g (L - x)`` by least squares over the places with a finite,
    positive amplitude; ``a0 exp(g d)`` gives g. g > 0: waves grow as they travel
    upstream (away from the meter); g < 0: they decay.

    Parameters
    ----------
    x : ndarray (N,)
        Places, m from the inlet.
    amplitude : ndarray (N,)
        Amplitude at each place (e.g. :func:`temporal_sd`), any unit.
    length : float
        Position of the meter, x = L, m.

    Returns
    -------
    float
        g, 1/m; NaN with fewer than MIN_PLACES places.
    """
    a = np.asarray(amplitude, float)
    ok = np.isfinite(a) & (a > 0)
    if ok.sum() < MIN_PLACES:
        return float("nan")
    d = length - np.asarray(x, float)[ok]
    return float(np.polyfit(d, np.log(a[ok]), 1)[0])


@dataclass(frozen=True)
class WaveMeasures:
    """Measures 1-3 of one block field (SI).

    ``oscillation`` m/s (RMS over places of ``sd``); ``band_power``, ``total_variance``
    (m/s)^2, ``band_share`` 1, ``places`` used by the spectrum; ``x`` block centres, m,
    and ``sd`` the amplitude there, m/s; ``growth`` 1/m (:func:`growth_upstream`);
    ``short_power`` (m/s)^2 and ``short_share`` 1, the same as the band's in
    :data:`SHORT_WAVES_S`; ``peak_period`` s (:func:`peak_period`).
    """

    oscillation: float
    band_power: float
    total_variance: float
    band_share: float
    places: int
    x: np.ndarray
    sd: np.ndarray
    growth: float
    short_power: float = float("nan")
    short_share: float = float("nan")
    peak_period: float = float("nan")


def wave_measures(blocks: np.ndarray, dt: float, x: np.ndarray, length: float,
                  band: tuple[float, float] = STOP_AND_GO_S) -> WaveMeasures:
    """:func:`temporal_sd`, :func:`band_power` (in ``band`` and in
    :data:`SHORT_WAVES_S`), :func:`peak_period` and :func:`growth_upstream` of ``blocks``
    (T, N; m/s) with block duration ``dt`` (s), block centres ``x`` (m) and the meter at
    ``length`` (m)."""
    sd = temporal_sd(blocks)
    spectra = place_spectra(blocks, dt)
    p, short = spectra.band(band), spectra.band(SHORT_WAVES_S)
    return WaveMeasures(rms(sd), p["band_power"], p["total_variance"], p["band_share"],
                        int(p["places"]), np.asarray(x, float), sd,
                        growth_upstream(x, sd, length), short["band_power"],
                        short["band_share"], spectra.peak_period())


def block_centres(places: int, block_m: float) -> np.ndarray:
    """Centres (m from the inlet) of ``places`` blocks of ``block_m`` metres."""
    return (np.arange(places) + 0.5) * block_m


def snapshot_blocks(period: np.ndarray, pos: np.ndarray, speed: np.ndarray,
                    n_periods: int, periods_per_block: int, block_m: float,
                    length: float) -> np.ndarray:
    """Mean speed of vehicle samples per block of ``periods_per_block`` x ``block_m``.

    Parameters
    ----------
    period : ndarray of int (S,)
        Period index of each sample, 0 .. n_periods - 1.
    pos, speed : ndarray (S,)
        Position (m from the inlet) and speed (m/s) of each sample.
    n_periods : int
        Periods observed; an incomplete trailing block of periods or metres is dropped.
    periods_per_block : int
        Periods per block (>= 1).
    block_m : float
        Block length, m.
    length : float
        Section length, m.

    Returns
    -------
    ndarray (n_periods // periods_per_block, floor(length / block_m))
        m/s; NaN in a block with no sample.
    """
    bt, bx = n_periods // periods_per_block, int(length // block_m + 1e-9)
    it = np.asarray(period, np.intp) // periods_per_block
    ix = (np.asarray(pos, float) // block_m).astype(np.intp)
    keep = (it < bt) & (ix >= 0) & (ix < bx)
    idx = it[keep] * bx + ix[keep]
    n = np.bincount(idx, minlength=bt * bx)
    s = np.bincount(idx, weights=np.asarray(speed, float)[keep], minlength=bt * bx)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, s / np.maximum(n, 1), np.nan).reshape(bt, bx)


def _occupied_runs(occupied: np.ndarray, min_gap: int) -> list[tuple[int, int]]:
    """(start, stop) bin ranges of runs of occupied bins, runs separated by fewer than
    ``min_gap`` empty bins merged (a sparse tail of a file is not a gap)."""
    idx = np.flatnonzero(occupied)
    if not idx.size:
        return []
    splits = np.flatnonzero(np.diff(idx) > min_gap) + 1
    return [(int(r[0]), int(r[-1]) + 1) for r in np.split(idx, splits)]


def file_boundaries(lat: np.ndarray, bin_m: float = 0.1, min_gap_m: float = 0.3,
                    empty_share: float = 0.002, min_share: float = 0.02) -> np.ndarray:
    """Lateral offsets that separate the files of a class, m (empty: one file).

    A histogram of the lateral offsets in bins of ``bin_m``; a bin holding at most
    ``empty_share`` of the samples counts as empty (vehicles moving between files cross
    the gaps); runs of occupied bins apart by at least ``min_gap_m`` of empty bins are
    files, those holding less than ``min_share`` of the samples dropped. A boundary lies
    midway across each gap between neighbouring files.

    Parameters
    ----------
    lat : ndarray (S,)
        Lateral offset of each sample from the lane centre, m (NaN skipped).

    Returns
    -------
    ndarray (files - 1,)
        Increasing boundaries, m; assign samples with ``numpy.searchsorted``.
    """
    v = np.asarray(lat, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return np.empty(0)
    edges = np.arange(v.min(), v.max() + bin_m, bin_m)
    edges = edges if edges.size >= 2 else np.array([v.min(), v.min() + bin_m])
    counts, edges = np.histogram(v, bins=edges)
    runs = _occupied_runs(counts > empty_share * v.size,
                          max(1, int(np.ceil(min_gap_m / bin_m - 1e-9))))
    kept = [(a, b) for a, b in runs if counts[a:b].sum() >= min_share * v.size]
    return np.array([(edges[b0] + edges[a1]) / 2
                     for (_, b0), (a1, _) in pairwise(kept)])


def speed_spread(speed: np.ndarray) -> float:
    """Sample sd (ddof 1) of per-vehicle speed samples, m/s: the spread across vehicles
    (lateral files, the mean profile and waves alike); NaN with fewer than two."""
    v = np.asarray(speed, float)
    v = v[np.isfinite(v)]
    return float(np.std(v, ddof=1)) if v.size > 1 else float("nan")


@dataclass(frozen=True)
class LateralFile:
    """One lateral file of a class: ``centre`` (mean lateral offset, m), ``share`` of the
    class's samples (1), ``samples`` (count), ``speed_mean`` and ``speed_spread`` (m/s)."""

    centre: float
    share: float
    samples: int
    speed_mean: float
    speed_spread: float


def lateral_files(lat: np.ndarray, speed: np.ndarray,
                  **histogram: float) -> tuple[np.ndarray, list[LateralFile]]:
    """The files of one class's samples and which file each sample rides in.

    Parameters
    ----------
    lat, speed : ndarray (S,)
        Lateral offset (m) and speed (m/s) of each sample.
    **histogram
        Options of :func:`file_boundaries`.

    Returns
    -------
    labels : ndarray of int (S,)
        File of each sample, 0 for the lowest lateral offset (SUMO: the rightmost).
    files : list of LateralFile
        In that order; the shares sum to 1 (every sample is in a file).
    """
    lat, speed = np.asarray(lat, float), np.asarray(speed, float)
    labels = np.searchsorted(file_boundaries(lat, **histogram), lat)
    files = []
    for k in range(int(labels.max()) + 1 if labels.size else 0):
        m = labels == k
        files.append(LateralFile(float(lat[m].mean()), float(m.sum() / lat.size),
                                 int(m.sum()), float(speed[m].mean()),
                                 speed_spread(speed[m])))
    return labels, files
