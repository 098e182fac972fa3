"""The section-count trend test (arzsumo.evaluation.stationarity)."""

import numpy as np
import pytest

from arzsumo.evaluation.stationarity import count_trend


def test_a_linear_ramp_is_measured_and_called_a_trend():
    t = np.arange(450.0)
    n = 140.0 + 2.0 * t / 60.0                      # +2 veh/min
    tr = count_trend(n, 1.0)
    assert tr.slope_veh_min == pytest.approx(2.0, rel=1e-9)
    assert tr.blocks == 15 and tr.block_s == 30.0
    assert tr.kendall_p < 1e-6 and not tr.stationary
    assert tr.drift == pytest.approx(2.0 * 7.5 / n.mean(), rel=1e-9)


def test_noise_around_a_level_is_stationary_in_most_replications():
    rng = np.random.default_rng(0)
    calls = [count_trend(140 + rng.normal(0, 3, 450), 1.0).stationary for _ in range(200)]
    # Kendall at alpha 0.05 rejects about 5 % of trend-free series
    assert 0.88 <= np.mean(calls) <= 0.99


def test_a_constant_series_is_stationary_and_short_series_are_refused():
    assert count_trend(np.full(300, 50.0), 1.0).stationary
    with pytest.raises(ValueError, match="at least 3"):
        count_trend(np.ones(60), 1.0)
    with pytest.raises(ValueError, match="NaN"):
        count_trend(np.array([1.0, np.nan] * 100), 1.0)
