"""Wave measures of a speed field: oscillation, stop-and-go band power, growth upstream.

The per-vehicle speed sd mostly measures the speed gap between *lateral files* (vehicles
side by side in SUMO's wide lane), not waves; these measures take the fluctuation in time
of block-mean speeds at each place (:func:`arzsumo.evaluation.fields.block_means`): each
place's sd over time, the power of its periodogram in the stop-and-go band
(:data:`STOP_AND_GO_S`) and the short waves' band, the peak period, the growth of the
amplitude upstream, and the lateral files of a class so that each is taken per file.
docs/outputs.md, ``section.waves``. Pure numpy/scipy, SI (m, s, m/s);
:func:`wave_measures` bundles them.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from scipy.signal import periodogram

from arzsumo.evaluation.fields import temporal_var

#: the stop-and-go band: periods from 1 to 10 min, s
STOP_AND_GO_S = (60.0, 600.0)
#: the short waves' band: periods from 20 s to 1 min, s (resolved on blocks of <= 10 s);
#: where the IDM stream's stop-and-go has most of its power (peaks at 43-64 s)
SHORT_WAVES_S = (20.0, 60.0)
#: fewest blocks of a place's series for a spectrum; fewest places for a growth slope
MIN_BLOCKS, MIN_PLACES = 8, 3


def temporal_sd(blocks: np.ndarray) -> np.ndarray:
    """Each place's sample sd over time (N,) of ``blocks`` (T, N; m/s, NaN where a block
    holds no vehicle): ddof 1, NaN skipped; NaN at a place with fewer than two blocks."""
    return np.sqrt(np.maximum(temporal_var(np.asarray(blocks, float)), 0.0))


def rms(values: np.ndarray) -> float:
    """Root mean square of the finite values (NaN when none)."""
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
    series used, at frequencies ``f`` (F,; Hz). P may be 0."""

    f: np.ndarray
    psd: np.ndarray

    def band(self, band: tuple[float, float]) -> dict[str, float]:
        """Power in ``band`` (shortest, longest period, s): ``band_power`` and
        ``total_variance`` (over all frequencies above 0), means over the places, (m/s)^2;
        ``band_share``, their ratio; ``places`` used; NaN without any. A sine of amplitude
        A and a period inside the band gives A^2 / 2 and a share near 1."""
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
        """Periods (s, longest first; frequency 0 left out) and the places' mean density."""
        if not self.psd.shape[0] or self.f.size < 2:
            return np.zeros(0), np.zeros(0)
        return 1.0 / self.f[1:], self.psd[:, 1:].mean(axis=0)

    def peak_period(self) -> float:
        """The period (s) where :meth:`mean` is largest: the waves' dominant period; NaN
        without a place, a resolved frequency or any power (a field standing still)."""
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


def mean_periodogram(blocks: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Periods (s, longest first; frequency 0 left out) and the places' mean one-sided
    periodogram density ((m/s)^2 s) of ``blocks`` (T, N; as :func:`place_spectra`); both
    empty without a place used."""
    return place_spectra(blocks, dt).mean()


def growth_upstream(x: np.ndarray, amplitude: np.ndarray, length: float) -> float:
    """Log-linear slope g (1/m) of ``amplitude`` against the distance upstream from x = ``length``.

    Fits ``log a = c + g (L - x)`` by least squares over the places ``x`` (m from the
    inlet) with a finite, positive amplitude (any unit, e.g. :func:`temporal_sd`). g > 0:
    waves grow as they travel upstream (away from the meter at L); NaN with fewer than
    MIN_PLACES places.
    """
    a = np.asarray(amplitude, float)
    ok = np.isfinite(a) & (a > 0)
    if ok.sum() < MIN_PLACES:
        return float("nan")
    d = length - np.asarray(x, float)[ok]
    return float(np.polyfit(d, np.log(a[ok]), 1)[0])


@dataclass(frozen=True)
class WaveMeasures:
    """The wave measures of one block field (SI).

    ``oscillation`` m/s (RMS over places of ``sd``); ``band_power``, ``total_variance``
    (m/s)^2, ``band_share`` 1, ``places`` used by the spectrum; ``x`` block centres, m,
    and ``sd`` the amplitude there, m/s; ``growth`` 1/m (:func:`growth_upstream`);
    ``short_power`` (m/s)^2 and ``short_share`` 1, the same as the band's in
    :data:`SHORT_WAVES_S`; ``peak_period`` s (:meth:`PlaceSpectra.peak_period`).
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
    """:func:`temporal_sd`, the power (:meth:`PlaceSpectra.band`, in ``band`` and in
    :data:`SHORT_WAVES_S`), the peak period and :func:`growth_upstream` of ``blocks``
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
    """Mean speed (m/s) of vehicle samples per block of ``periods_per_block`` x ``block_m``.

    Samples: ``period`` index (0 .. n_periods - 1), ``pos`` (m from the inlet) and
    ``speed`` (m/s), each (S,). Returns (n_periods // periods_per_block,
    floor(length / block_m)), an incomplete trailing block of periods or metres dropped;
    NaN in a block with no sample.
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
    midway across each gap between neighbouring files. ``lat``: each sample's offset
    from the lane centre, m (NaN skipped). Returns the increasing boundaries (files - 1,),
    m; assign samples with ``numpy.searchsorted``.
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
    """The files of one class's samples (``lat`` m, ``speed`` m/s, each (S,); ``histogram``:
    options of :func:`file_boundaries`) and which file each sample rides in.

    Returns ``labels`` (S,), the file of each sample, 0 for the lowest lateral offset (SUMO:
    the rightmost), and the :class:`LateralFile` list in that order (shares sum to 1).
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
