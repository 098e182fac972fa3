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


def _carried(c: float, rng: np.random.Generator, noise: float = 0.05) -> np.ndarray:
    """A random profile carried at c (m/s) past 20 places 50 m apart, 1 s for 600 s, on
    a place-dependent mean, with some noise and one cell empty for 10 s."""
    t = np.arange(600.0)[:, None]
    x = 25.0 + 50.0 * np.arange(20)[None, :]
    base = np.cumsum(rng.normal(0.0, 1.0, 6000))
    f = np.interp(t - x / c + 3000.0, np.arange(6000.0), base) + 0.01 * x
    f += rng.normal(0.0, noise, f.shape)
    f[100:110, 3] = np.nan
    return f


@pytest.mark.parametrize("c", [20.8, -13.9, -3.1])     # 75 km/h down, 50 and 11 up
def test_wave_travel_recovers_the_speed_of_a_travelling_field(c):
    out = wave_travel(_carried(c, np.random.default_rng(7)), dt=1.0, dx=50.0, gap=5,
                      max_lag_s=150.0)
    assert out["lag_s"] == pytest.approx(250.0 / c, abs=0.5)
    assert abs(out["speed"] - c) / abs(c) < 0.05
    assert out["peak_corr"] > 0.9 and out["pairs"] == 15


def test_wave_travel_gives_no_speed_beyond_what_it_resolves():
    rng = np.random.default_rng(9)
    # slower than 250 m in 60 s: the peak sits at the edge of the search
    slow = wave_travel(_carried(-3.1, rng), dt=1.0, dx=50.0, gap=5, max_lag_s=60.0)
    assert slow["lag_s"] == -60.0 and np.isnan(slow["speed"])
    # the same signal everywhere at once: lag 0, no direction
    common = np.repeat(np.cumsum(rng.normal(size=(600, 1)), axis=0), 20, axis=1)
    same = wave_travel(common + rng.normal(0, 0.1, common.shape), 1.0, 50.0, 5, 60.0)
    assert abs(same["lag_s"]) < 2 and np.isnan(same["speed"])


def test_wave_travel_of_unrelated_noise_is_weakly_correlated():
    rng = np.random.default_rng(8)
    out = wave_travel(rng.normal(size=(600, 20)), dt=1.0, dx=50.0, gap=5, max_lag_s=60.0)
    assert out["peak_corr"] < 0.25
