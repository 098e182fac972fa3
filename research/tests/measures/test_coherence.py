"""The coherent share against fields with a known answer.

A field ``v(t, x) = a(x) (h * b)(t - tau(x)) + n(t, x)``, with the noise n independent of
the boundary series b, has in each band the coherent share signal / (signal + noise
power) there. With b and n both AR(1) of the same coefficient the share is the same in
every band, a^2 / (a^2 + sigma^2); with a low-pass h and white b and n it differs per
band and is summed over the estimator's own bins.
"""

from __future__ import annotations

import numpy as np
import pytest
from arzsumo_studies.measures.coherence import (
    BANDS_S,
    CoherenceError,
    boundary_shares,
    coherent_share,
    effective_segments,
    spectral_surrogate,
    surrogate_floor,
    travel_lags,
)
from scipy.signal import lfilter, welch

from arzsumo.errors import ArzsumoError

DT, L = 1.0, 1000.0
X = np.arange(25.0, L, 50.0)                      # 20 cells of 50 m, m
LAMBDA_4, V_H = -9.06, 8.4                        # the default stream's speeds, m/s
PHI = 0.9                                         # AR(1) coefficient at 1 s


def ar1(rng: np.random.Generator, shape: tuple[int, ...], phi: float = PHI) -> np.ndarray:
    """AR(1) along axis 0 with unit innovations."""
    return lfilter([1.0], [1.0, -phi], rng.standard_normal(shape), axis=0)


def driven_field(rng: np.random.Generator, n_t: int, share: np.ndarray, scale: np.ndarray,
                 lag_s: np.ndarray, kernel: tuple[list[float], list[float]] = ([1.0], [1.0]),
                 boundary: np.ndarray | None = None, noise_phi: float = PHI
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(v (T, N), b (T,)): v = a (h * b)(t - lag) + noise of the share's power (for h = 1
    and noise of b's spectrum; ``noise_phi`` 0 gives white noise of unit innovations
    scaled by sqrt((1 - share) / share) a)."""
    lag = np.rint(lag_s / DT).astype(int)
    d = int(max(lag.max(), 0))
    full = ar1(rng, (n_t + d,)) if boundary is None else boundary
    driven = lfilter(*kernel, full)
    v = np.empty((n_t, share.size))
    for j in range(share.size):
        signal = scale[j] * driven[d - lag[j]: d - lag[j] + n_t]
        noise = ar1(rng, (n_t,), noise_phi) * scale[j] * np.sqrt((1 - share[j]) / share[j])
        v[:, j] = 20.0 + signal + noise
    return v, full[d: d + n_t]


def test_the_share_is_the_signal_s_share_of_the_power_whatever_the_scale_and_delay():
    rng = np.random.default_rng(1)
    share = np.resize([0.2, 0.5, 0.8], X.size)
    scale = np.resize([0.3, 1.0, 3.0, 10.0], X.size)            # m/s per unit of b
    lag = travel_lags(X, L, LAMBDA_4)                            # 2.8 .. 107 s upstream
    v, b = driven_field(rng, 8 * 3600, share, scale, lag)
    res = coherent_share(v, b, DT, X, lag_s=lag)
    assert res.segment_s == 1200.0 and list(res.band_names) == list(BANDS_S)
    assert res.bins.tolist() == [41, 19]                         # 20-60 s, 60-600 s at 1/1200 Hz
    floor = res.floor
    assert floor.max() < 0.025
    np.testing.assert_allclose(res.share, np.broadcast_to(share, res.share.shape), atol=0.05)
    for s in (0.2, 0.5, 0.8):
        same = res.share[:, share == s]                          # scales 0.3-10, delays 3-107 s
        assert np.ptp(same, axis=1).max() < 0.08
        # their mean: the known share plus the estimator's bias (1 - s)^2 / n_eff
        np.testing.assert_allclose(same.mean(axis=1), s + (1 - s) ** 2 * floor.mean(),
                                   atol=0.015)
    want = (share * res.power).sum(axis=1) / res.power.sum(axis=1)
    np.testing.assert_allclose(res.share_section, want, atol=0.03)
    np.testing.assert_allclose(res.share_plain, share.mean(), atol=0.03)
    assert np.all(res.beyond_floor < res.share_section)


def test_the_share_follows_the_filter_band_by_band():
    rng = np.random.default_rng(2)
    alpha, noise = 0.95, 0.1                      # a low pass (corner ~125 s), white noise
    b = rng.standard_normal(8 * 3600)             # white, unit variance
    signal = lfilter([1 - alpha], [1.0, -alpha], b)
    v = 20.0 + signal[:, None] + np.sqrt(noise) * rng.standard_normal((b.size, X.size))
    res = coherent_share(v, b, DT, X)
    h2 = (1 - alpha) ** 2 / np.abs(1 - alpha * np.exp(-2j * np.pi * res.f * DT)) ** 2
    for k, (short, long) in enumerate(BANDS_S.values()):
        inside = (res.f >= 1 / long) & (res.f <= 1 / short)
        known = h2[inside].sum() / (h2[inside] + noise).sum()   # both densities x 2 dt
        np.testing.assert_allclose(res.share_section[k], known, atol=0.04)
    assert res.share_section[0] < 0.45 < 0.8 < res.share_section[1]   # the bands differ


def test_independent_noise_sits_on_the_reported_floor_pooled_over_runs():
    rng = np.random.default_rng(3)
    runs = 20                                                    # 20 seeds of 450 s
    v = [20.0 + ar1(rng, (450, X.size)) for _ in range(runs)]
    b = [ar1(rng, (450,)) for _ in range(runs)]
    res = coherent_share(v, b, DT, X)
    assert res.segment_s == 224.0 and res.runs == runs
    one = effective_segments(450, 224)                           # 3 segments at 50 %
    assert one == pytest.approx(3 / (1 + 2 * (2 / 3) / 36), rel=0.01)
    np.testing.assert_allclose(res.floor, 1 / (runs * one))
    # within the estimate's spread (sd about 0.002 here); the lowest bin (224 s, in the
    # stop-and-go band) reads about 25 % above 1 / n_eff (module docstring)
    assert np.all(res.share_section > 0.7 * res.floor_section)
    assert np.all(res.share_section < 1.4 * res.floor_section)
    np.testing.assert_allclose(res.beyond_floor, 0.0, atol=0.01)
    measured = surrogate_floor(v, b, DT, X, surrogates=10, seed=4)
    assert measured.shape == (10, 2)
    np.testing.assert_allclose(measured.mean(axis=0), res.floor_section, rtol=0.2)


def test_one_short_record_has_a_high_floor():
    rng = np.random.default_rng(5)
    res = coherent_share(20.0 + ar1(rng, (450, X.size)), ar1(rng, (450,)), DT, X)
    assert res.floor[0] == pytest.approx(0.346, abs=0.002)
    np.testing.assert_allclose(res.share_section, res.floor_section, atol=0.08)


def test_surrogates_lose_a_real_coherence():
    rng = np.random.default_rng(6)
    v, b = driven_field(rng, 4 * 3600, np.full(X.size, 0.8), np.ones(X.size), np.zeros(X.size))
    res = coherent_share(v, b, DT, X)
    assert res.share_section.min() > 0.75
    measured = surrogate_floor(v, b, DT, X, surrogates=5, seed=7).mean(axis=0)
    np.testing.assert_allclose(measured, res.floor_section, rtol=0.2)


def test_an_unaligned_delay_pulls_the_estimate_down_and_the_lag_restores_it():
    rng = np.random.default_rng(8)
    lag = np.full(X.size, 100.0)                                 # s, in 225 s segments
    v, b = driven_field(rng, 20 * 450, np.full(X.size, 0.8), np.ones(X.size), lag)
    aligned = coherent_share(v, b, DT, X, lag_s=lag, segment_s=225.0).share_section
    unaligned = coherent_share(v, b, DT, X, segment_s=225.0).share_section
    np.testing.assert_allclose(aligned, 0.8, atol=0.05)
    assert np.all(unaligned < aligned - 0.3)


def test_a_field_driven_by_the_inlet_is_coherent_with_q0_not_with_qL():
    rng = np.random.default_rng(9)
    lag_in = travel_lags(X, 0.0, V_H)                            # downstream at the speed
    v, q0 = driven_field(rng, 8 * 3600, np.full(X.size, 0.6), np.ones(X.size), lag_in)
    q_l = ar1(rng, (q0.size,))                                   # the outlet: independent
    u = np.full(q0.size, 0.05)                                   # a held input, veh/s
    res = boundary_shares(v, {"q0": q0, "qL": q_l, "U": u}, DT, X,
                          lags={"q0": lag_in, "qL": travel_lags(X, L, LAMBDA_4)})
    table = res.table().set_index(["boundary", "band"])
    assert len(table) == 6
    np.testing.assert_allclose(table.loc["q0", "share"], 0.6, atol=0.04)
    np.testing.assert_allclose(table.loc["qL", "share"], table.loc["qL", "floor"], atol=0.02)
    np.testing.assert_allclose(table.loc["qL", "beyond_floor"], 0.0, atol=0.02)
    assert (table.loc["U", "share"] == 0.0).all()                # nothing in a held series
    assert (table.loc["U", "boundary_power"] == 0.0).all()
    assert table.loc["U", "beyond_floor"].isna().all()          # no floor to stand above
    cells = res.cells()
    assert len(cells) == 3 * 2 * X.size
    assert set(cells.columns) == {"boundary", "band", "x_m", "share", "power", "floor"}


def test_a_spectral_surrogate_keeps_the_mean_and_the_spectrum_on_average():
    rng = np.random.default_rng(10)
    b = 3.0 + ar1(rng, (4 * 3600,))
    c = spectral_surrogate(b, rng, smooth_bins=6)
    assert c.mean() == pytest.approx(b.mean())
    assert c.size == b.size and np.corrcoef(b, c)[0, 1] == pytest.approx(0.0, abs=0.05)
    _, pb = welch(b, nperseg=1200)
    _, pc = welch(c, nperseg=1200)
    np.testing.assert_allclose(pc[1:100].sum(), pb[1:100].sum(), rtol=0.1)


GOOD = {"v": np.zeros((100, 3)), "b": np.arange(100.0), "dt": 1.0, "x": [0.0, 50.0, 100.0]}
NAN = np.zeros((100, 3))
NAN[5:8, 1] = np.nan


@pytest.mark.parametrize(("changes", "match"), [
    ({"v": np.zeros(100)}, r"v\[0\] = an array of shape \(100,\) is not allowed: a speed"),
    ({"b": np.zeros(99)}, r"b\[0\] = an array of shape \(99,\) is not allowed: a series of "
                          r"the field's 100 periods"),
    ({"v": NAN}, r"v\[0\] = 3 non-finite values is not allowed: finite speeds \(fill empty"),
    ({"b": np.full(100, np.inf)}, r"b\[0\] = 100 non-finite values is not allowed"),
    ({"dt": 0.0}, r"dt = 0.0 is not allowed: a period > 0, s"),
    ({"x": [0.0, 50.0]}, r"x = an array of shape \(2,\) is not allowed: 3 finite cell"),
    ({"bands": {"w": (60.0, 20.0)}}, r"bands = .* is not allowed: \(shortest, longest\)"),
    ({"segment_s": 200.0}, r"segment_s = 200.0 is not allowed: a segment of 8 to 100"),
    ({"lag_s": 80.0}, r"lag_s = 80.0 is not allowed: lags leaving a segment of 50.0 s"),
    ({"lag_s": [1.0, 2.0]}, r"lag_s = an array of shape \(2,\) is not allowed: one lag"),
    ({"v": [np.zeros((100, 3))] * 2, "b": [np.zeros(100)]},
     r"b = 1 runs is not allowed: one boundary series per speed field \(2 runs\)"),
    ({"v": [np.zeros((100, 3)), np.zeros((100, 2))], "b": [np.zeros(100)] * 2},
     r"v\[1\] = an array of shape \(100, 2\) is not allowed: the same 3 cells"),
])
def test_bad_inputs_are_refused_with_the_argument_named(changes, match):
    args = {**GOOD, **changes}
    with pytest.raises(CoherenceError, match=match) as caught:
        coherent_share(args.pop("v"), args.pop("b"), args.pop("dt"), args.pop("x"), **args)
    assert isinstance(caught.value, ValueError) and isinstance(caught.value, ArzsumoError)
    assert "\n" not in str(caught.value)


def test_lags_of_unknown_boundaries_and_bad_wave_speeds_are_refused():
    with pytest.raises(CoherenceError, match=r"lags = \['q9'\] is not allowed"):
        boundary_shares(GOOD["v"], {"q0": GOOD["b"]}, 1.0, GOOD["x"], lags={"q9": 0.0})
    with pytest.raises(CoherenceError, match=r"speed = 0.0 is not allowed"):
        travel_lags(GOOD["x"], L, 0.0)
