"""The deviation norm and the decay time, on fields and norms whose answers are known."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from arzsumo.evaluation.decay import (
    decay,
    deviation_norm,
    moving_mean,
    stationary_band,
    stationary_state,
)

S = np.array([[0.1] * 5, [8.0] * 5, [0.02] * 5, [8.0] * 5])      # veh/m, m/s (4, cells)


def test_stationary_state_is_the_time_mean_without_nan():
    f = np.stack([S, 3 * S])
    f[0, 2, 1] = np.nan                           # no AV passed cell 1 in period 0
    got = stationary_state(f)
    want = 2 * S
    want[2, 1] = 3 * S[2, 1]
    assert np.allclose(got, want)
    assert np.isnan(stationary_state(np.full((3, 4, 2), np.nan))).all()


@pytest.mark.parametrize("a", [0.0, 0.1, -0.25])
def test_a_uniform_relative_offset_has_its_size_as_norm(a):
    f = np.stack([S * (1 + a)] * 3)
    f[1, 3, 4] = np.nan                           # NaN cells are left out, not zeros
    assert np.allclose(deviation_norm(f, S), abs(a))


def test_a_field_without_a_stationary_level_is_left_out_quietly():
    s = S.copy()
    s[1] = np.nan                                 # no AVs: their density has no level
    f = np.stack([s * 1.1] * 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.allclose(deviation_norm(f, s), 0.1)


def test_an_open_loop_without_a_finite_norm_has_no_band_and_says_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(stationary_band(np.full(50, np.nan), 1.0))


def test_densities_and_speeds_weigh_alike():
    f = S.copy()[None]
    f[0, 0] *= 1.2                                # +20 % HV density, the rest exact
    assert deviation_norm(f, S)[0] == pytest.approx(np.sqrt(0.2 ** 2 / 4))


def test_moving_mean_is_the_trailing_mean():
    e = np.random.default_rng(1).random(50)
    got = moving_mean(e, 5)
    assert np.allclose(got[4:], np.convolve(e, np.ones(5) / 5, "valid"))
    assert np.allclose(got[:4], np.cumsum(e[:4]) / np.arange(1, 5))


def test_an_exponential_decay_ends_where_it_crosses_the_band():
    t = np.arange(0.0, 450.0)
    e = 0.1 + np.exp(-t / 20.0)
    band = 0.1 + np.exp(-60.5 / 20.0)
    d = decay(t, e, band, period=1.0, smooth=1.0)
    assert d.decay_time_s == 60.0 and d.decayed
    assert d.deviation_integral_s == pytest.approx(np.sum(e))
    assert d.deviation_excess_s == pytest.approx(np.sum(np.maximum(e - band, 0)))


def test_never_above_is_zero_and_ending_above_is_not_decayed():
    t = np.arange(0.0, 100.0)
    assert decay(t, np.full(100, 0.2), 0.3, 1.0).decay_time_s == 0.0
    d = decay(t, np.where(t < 10, 0.8, 0.1), 0.3, 1.0, smooth=1.0)
    assert d.decay_time_s == 9.0 and d.deviation_excess_s == pytest.approx(5.0)
    late = decay(t, np.where(t > 90, 0.8, 0.1), 0.3, 1.0, smooth=1.0)
    assert not late.decayed and late.decay_time_s == 99.0


def test_the_band_is_the_95th_percentile_of_the_smoothed_open_loop():
    e = np.linspace(0, 1, 1001)
    assert stationary_band(e, 1.0, smooth=1.0) == pytest.approx(0.95)
