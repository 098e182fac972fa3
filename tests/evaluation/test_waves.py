"""Wave measures on synthetic fields with known answers (no SUMO)."""

import numpy as np
import pytest

from arzsumo.evaluation.fields import block_means, oscillation
from arzsumo.evaluation.waves import (
    STOP_AND_GO_S,
    block_centres,
    file_boundaries,
    growth_upstream,
    lateral_files,
    place_spectra,
    snapshot_blocks,
    speed_spread,
    temporal_sd,
    wave_measures,
)


def band_power(blocks: np.ndarray, dt: float,
               band: tuple[float, float] = STOP_AND_GO_S) -> dict[str, float]:
    """The places' mean spectral power of ``blocks`` (T, N) in ``band`` (periods, s)."""
    return place_spectra(blocks, dt).band(band)


def peak_period(blocks: np.ndarray, dt: float) -> float:
    """The period (s) of the places' mean periodogram's peak."""
    return place_spectra(blocks, dt).peak_period()

L, DX, DT = 1000.0, 50.0, 1.0          # section, control cells (m), control period (s)
X = (np.arange(20) + 0.5) * DX
T = np.arange(1800) * DT               # a 30 min window


def _blocks(field: np.ndarray) -> np.ndarray:
    """100 m x 10 s block means of a (T, N) field on the control grid."""
    return block_means(field[:, None, :], 10, 2)[:, 0]


def _travelling(period_s: float, amp: float, c: float = -4.0) -> np.ndarray:
    """A profile plus a sine travelling at c (m/s; < 0 upstream), on the control grid."""
    phase = 2 * np.pi * (T[:, None] - X[None, :] / c) / period_s
    return 20.0 - 0.005 * X[None, :] + amp * np.sin(phase)


def _damped(period_s: float, amp: float, c: float = -4.0) -> float:
    """Amplitude of the travelling sine after 100 m x 10 s block means: the mean of 10
    samples 1 s apart, times that of 2 cells 50 m (50 / |c| s of phase) apart."""
    f = 1.0 / period_s
    in_time = np.sin(10 * np.pi * f) / (10 * np.sin(np.pi * f))
    return amp * in_time * np.cos(np.pi * f * DX / abs(c))


def test_a_three_minute_wave_is_all_in_the_stop_and_go_band():
    amp = 3.0
    blocks = _blocks(_travelling(180.0, amp))
    p = band_power(blocks, 10.0)
    damped = _damped(180.0, amp)
    assert damped == pytest.approx(0.97 * amp, abs=0.01)
    assert p["band_power"] == pytest.approx(damped ** 2 / 2, rel=0.01)
    assert p["band_share"] == pytest.approx(1.0, abs=0.02)
    assert p["places"] == 10
    assert p["total_variance"] == pytest.approx(damped ** 2 / 2, rel=0.03)


def test_a_twenty_second_flicker_has_no_power_in_the_band():
    field = _travelling(20.0, 3.0)
    blocks = block_means(field[:, None, :], 4, 2)[:, 0]    # 4 s blocks resolve 20 s
    p = band_power(blocks, 4.0)
    assert p["total_variance"] > 0.3
    assert p["band_power"] < 1e-3 * p["total_variance"]
    assert p["band_share"] < 1e-3


def test_a_fifty_second_wave_peaks_at_its_period_in_the_short_band():
    """The IDM stream's stop-and-go period: on 10 s blocks over 30 min the periodogram's
    frequencies are k / 1800 s, so 50 s (k = 36) is one of them and the peak is exact."""
    amp = 3.0
    blocks = _blocks(_travelling(50.0, amp))
    w = wave_measures(blocks, 10.0, block_centres(10, 100.0), L)
    damped = _damped(50.0, amp)
    assert w.peak_period == pytest.approx(50.0, rel=1e-12)
    assert w.short_power == pytest.approx(damped ** 2 / 2, rel=0.02)
    assert w.short_share == pytest.approx(1.0, abs=0.02)
    assert w.band_share < 0.02                           # nothing at 1-10 min
    three_minutes = wave_measures(_blocks(_travelling(180.0, amp)), 10.0,
                                  block_centres(10, 100.0), L)
    assert three_minutes.peak_period == pytest.approx(180.0, rel=1e-12)
    assert three_minutes.short_share < 0.02


def test_no_place_and_a_standstill_have_no_peak():
    assert np.isnan(peak_period(np.full((45, 3), np.nan), 10.0))
    assert np.isnan(peak_period(np.zeros((45, 3)), 10.0))     # a deadlocked section


def test_a_steady_profile_has_neither_oscillation_nor_band_power():
    blocks = _blocks(_travelling(180.0, 0.0))
    assert np.allclose(temporal_sd(blocks), 0.0)
    assert band_power(blocks, 10.0)["band_power"] == pytest.approx(0.0, abs=1e-20)


def test_the_oscillation_is_that_of_fields():
    field = _travelling(240.0, 2.0) + np.random.default_rng(3).normal(0, 0.5, (T.size, 20))
    w = wave_measures(_blocks(field), 10.0, block_centres(10, 100.0), L)
    assert w.oscillation == pytest.approx(float(oscillation(field[:, None], 10, 2)[0]))
    assert w.x.tolist() == [50.0 + 100.0 * k for k in range(10)]


def test_an_amplitude_growing_upstream_gives_its_rate():
    g = 1.5e-3                                    # 1/m: e-fold every 667 m upstream
    amp = 0.5 * np.exp(g * (L - X))
    phase = 2 * np.pi * (T[:, None] + X[None, :] / 4.0) / 180.0
    field = 20.0 + amp[None, :] * np.sin(phase)
    blocks = _blocks(field)
    w = wave_measures(blocks, 10.0, block_centres(10, 100.0), L)
    assert w.growth == pytest.approx(g, rel=0.03)
    assert growth_upstream(X, amp[::-1], L) == pytest.approx(-g, rel=1e-9)   # decay
    assert np.isnan(growth_upstream(X[:2], amp[:2], L))


def test_missing_blocks_are_filled_and_sparse_places_skipped():
    blocks = _blocks(_travelling(180.0, 3.0))
    blocks[::7, 0] = np.nan                   # a few holes: filled
    blocks[: blocks.shape[0] // 2, 1] = np.nan  # half empty: skipped
    p = band_power(blocks, 10.0)
    assert p["places"] == 9
    assert p["band_power"] == pytest.approx(_damped(180.0, 3.0) ** 2 / 2, rel=0.03)
    assert band_power(np.full((5, 3), 1.0), 10.0)["places"] == 0     # too short


def _two_files(rng: np.random.Generator, n: int = 4000):
    right = rng.random(n) < 0.68
    lat = np.where(right, -2.0, 2.0) + rng.normal(0, 0.15, n)
    speed = np.where(right, 27.0, 68.0) / 3.6 + rng.normal(0, 0.3, n)
    return lat, speed


def test_two_lateral_clusters_are_two_files_with_their_shares_and_speeds():
    rng = np.random.default_rng(1)
    lat, speed = _two_files(rng)
    lat[:10] = np.linspace(-1.5, 1.5, 10)           # a few vehicles between the files
    labels, files = lateral_files(lat, speed)
    assert len(files) == 2 and file_boundaries(lat).size == 1
    assert [f.centre for f in files] == pytest.approx([-2.0, 2.0], abs=0.05)
    assert files[0].share == pytest.approx(0.68, abs=0.02)
    assert sum(f.share for f in files) == pytest.approx(1.0)
    assert [f.speed_mean * 3.6 for f in files] == pytest.approx([27.0, 68.0], abs=0.5)
    assert labels[lat < -1.8].max() == 0 and labels[lat > 1.8].min() == 1


def test_one_cluster_is_one_file():
    rng = np.random.default_rng(2)
    lat = rng.normal(0.0, 0.3, 2000)
    labels, files = lateral_files(lat, rng.normal(14 / 3.6, 0.5, 2000))
    assert len(files) == 1 and files[0].share == 1.0 and (labels == 0).all()
    assert files[0].centre == pytest.approx(0.0, abs=0.05)
    assert lateral_files(np.empty(0), np.empty(0))[1] == []


def test_steady_files_do_not_oscillate_though_their_spread_is_large():
    """Two files each at a steady speed: per file the block speeds do not move in time,
    while the pooled spread across vehicles is about the gap between the files."""
    rng = np.random.default_rng(4)
    n_periods, per_period = 600, 60
    period = np.repeat(np.arange(n_periods), per_period)
    pos = rng.uniform(0, L, period.size)
    lat, _ = _two_files(rng, period.size)
    speed = np.where(lat < 0, 27.0, 68.0) / 3.6
    labels, files = lateral_files(lat, speed)
    assert len(files) == 2
    assert speed_spread(speed) * 3.6 > 15.0
    for k in range(2):
        m = labels == k
        blocks = snapshot_blocks(period[m], pos[m], speed[m], n_periods, 10, 100.0, L)
        assert blocks.shape == (60, 10)
        w = wave_measures(blocks, 10.0, block_centres(10, 100.0), L)
        assert w.oscillation == pytest.approx(0.0, abs=1e-9)
        assert files[k].speed_spread == pytest.approx(0.0, abs=1e-9)
    # the pooled blocks do move: the mix of the files in a block changes
    pooled = snapshot_blocks(period, pos, speed, n_periods, 10, 100.0, L)
    assert wave_measures(pooled, 10.0, block_centres(10, 100.0), L).oscillation > 0.1


def test_snapshot_blocks_average_the_samples_of_a_block():
    blocks = snapshot_blocks(np.array([0, 9, 10, 25]), np.array([10.0, 90.0, 150.0, 999.0]),
                             np.array([1.0, 3.0, 5.0, 7.0]), 25, 10, 100.0, L)
    assert blocks.shape == (2, 10)
    assert blocks[0, 0] == 2.0 and blocks[1, 1] == 5.0
    assert np.isnan(blocks[0, 1]) and np.isfinite(blocks).sum() == 2   # period 25 dropped
