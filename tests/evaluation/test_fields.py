"""Block means and block RMSE of space-time fields (arzsumo.evaluation.fields)."""

import numpy as np
import pytest

from arzsumo.evaluation.fields import block_means, field_rmse, oscillation, wave_travel


def test_block_means_average_over_blocks_and_skip_nan():
    f = np.arange(4 * 1 * 6, dtype=float).reshape(4, 1, 6)
    f[0, 0, 0] = np.nan
    m = block_means(f, 2, 3)
    assert m.shape == (2, 1, 2)
    assert m[0, 0, 0] == pytest.approx(np.mean([1, 2, 6, 7, 8]))
    assert m[1, 0, 1] == pytest.approx(np.mean([15, 16, 17, 21, 22, 23]))
    assert np.isnan(block_means(np.full((2, 1, 2), np.nan), 2, 2)).all()


def test_white_noise_rmse_falls_as_one_over_root_block_size():
    rng = np.random.default_rng(3)
    truth = np.ones((600, 2, 20))
    noisy = truth + rng.normal(0.0, 0.4, truth.shape)
    grid, n1 = field_rmse(noisy, truth)
    blocks, n2 = field_rmse(noisy, truth, periods=10, cells=2)
    assert grid == pytest.approx([0.4, 0.4], rel=0.02)
    assert blocks == pytest.approx(grid / np.sqrt(20), rel=0.05)
    assert n1.tolist() == [12000, 12000] and n2.tolist() == [600, 600]


def test_pairs_missing_in_either_field_are_left_out_of_both():
    obs = np.ones((2, 1, 2))
    pred = np.full((2, 1, 2), 3.0)
    obs[0, 0, 0] = np.nan
    pred[1, 0, 1] = 100.0
    value, n = field_rmse(obs, pred, periods=2, cells=2)
    # one block: observed mean 1, predicted mean of the three shared pairs (3, 3, 100)
    assert value[0] == pytest.approx(abs(1.0 - (3 + 3 + 100) / 3))
    assert n[0] == 1
    with pytest.raises(ValueError, match="expected >= 1"):
        block_means(obs, 0, 1)


def test_oscillation_ignores_the_profile_and_measures_the_wave():
    t = np.arange(1200.0)[:, None, None]
    x = np.arange(20.0)[None, None, :]
    profile = 10.0 + 2.0 * x                       # a mean profile: pooled sd about 11.5
    steady = np.broadcast_to(profile, (1200, 1, 20))
    assert oscillation(steady)[0] == pytest.approx(0.0, abs=1e-12)
    assert np.nanstd(steady) > 11.0
    wave = profile + 3.0 * np.sin(2 * np.pi * (t / 120.0 - x / 10.0))
    assert oscillation(wave)[0] == pytest.approx(3.0 / np.sqrt(2) * np.sqrt(1200 / 1199))
    # 10-period blocks keep a 120 s wave: the mean of 10 samples scales its amplitude by
    # the discrete sinc sin(pi 10/120) / (10 sin(pi/120)) only
    # (times sqrt(120 / 119): the sample sd of 120 blocks over exactly 10 wave periods)
    damped = 3.0 / np.sqrt(2) * np.sin(np.pi * 10 / 120) / (10 * np.sin(np.pi / 120))
    damped *= np.sqrt(120 / 119)
    assert oscillation(wave, periods=10)[0] == pytest.approx(damped, rel=1e-3)


def test_oscillation_skips_empty_places_and_needs_two_blocks():
    rng = np.random.default_rng(5)
    f = rng.normal(0.0, 2.0, (4000, 2, 3))
    f[:, 0, 0] = np.nan                            # a place never observed
    f[1:, 1, :] = np.nan                           # one period only: no sd
    value = oscillation(f)
    assert value[0] == pytest.approx(2.0, rel=0.03)
    assert np.isnan(value[1])


@pytest.mark.parametrize("c", [20.8, -13.9])           # 75 km/h downstream, 50 upstream
def test_wave_travel_recovers_the_speed_of_a_travelling_field(c):
    rng = np.random.default_rng(7)
    t = np.arange(600.0)[:, None]
    x = 25.0 + 50.0 * np.arange(20)[None, :]
    # a random profile carried at speed c, plus a place-dependent mean and some noise
    base = np.cumsum(rng.normal(0.0, 1.0, 4000))
    phase = (t - (x / c) + 2000.0).astype(float)
    f = np.interp(phase, np.arange(4000.0), base) + 0.01 * x
    f += rng.normal(0.0, 0.05, f.shape)
    f[100:110, 3] = np.nan                               # an empty cell for a while
    out = wave_travel(f, dt=1.0, dx=50.0, gap=5, max_lag_s=60.0)
    assert out["lag_s"] == pytest.approx(250.0 / c, abs=0.5)
    assert np.sign(out["speed"]) == np.sign(c)
    assert abs(out["speed"] - c) / abs(c) < 0.05
    assert out["peak_corr"] > 0.95 and out["pairs"] == 15


def test_wave_travel_of_unrelated_noise_is_weakly_correlated():
    rng = np.random.default_rng(8)
    out = wave_travel(rng.normal(size=(600, 20)), dt=1.0, dx=50.0, gap=5, max_lag_s=60.0)
    assert out["peak_corr"] < 0.25
