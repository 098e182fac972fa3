"""The actuator's authority read from a run's periods, on synthetic series with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arzsumo.evaluation.authority import authority, window_means


def test_window_means_drop_the_incomplete_window():
    np.testing.assert_array_equal(window_means(np.arange(7.0), 1.0, 3.0), [1.0, 4.0])
    np.testing.assert_array_equal(window_means(np.arange(4.0), 2.0, 4.0), [0.5, 2.5])


def test_gain_of_an_actuator_that_delivers_sixty_percent():
    rng = np.random.default_rng(3)
    period, n = 1.0, 3600
    u = np.repeat(rng.normal(0, 0.1, n // 60), 60)          # a new U every minute
    noise = rng.normal(0, 0.2, n)                            # the outflow's own scatter
    q = 0.6 + 0.6 * u + noise
    a = authority(u, q, period, 60.0)
    assert a.windows == 60
    assert a.gain == pytest.approx(0.6, abs=3 * a.gain_se)
    assert a.gain_se < 0.05                                  # 0.2 / sqrt(60) / (0.1 sqrt(59))
    assert a.u_sd == pytest.approx(np.std(window_means(u, period, 60.0), ddof=1))


def test_a_held_u_has_no_gain():
    a = authority(np.full(600, 0.1), np.random.default_rng(0).normal(0.6, 0.1, 600), 1.0)
    assert a.u_sd == 0.0 and math.isnan(a.gain) and a.windows == 10
