"""Block means and block RMSE of space-time fields (arzsumo.evaluation.fields)."""

import numpy as np
import pytest

from arzsumo.evaluation.fields import block_means, field_rmse


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
