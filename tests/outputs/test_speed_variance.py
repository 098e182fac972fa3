"""The run summary's speed variance: numpy's nanvar, and NaN without a warning when a
class has no speed sample in the window."""

from __future__ import annotations

import math
import warnings

import numpy as np

from arzsumo.outputs.bridge import finite_variance


def test_variance_of_the_samples_and_nan_without_a_warning_when_there_is_none():
    with warnings.catch_warnings():
        warnings.simplefilter("error")                     # any warning fails the test
        assert math.isnan(finite_variance(np.full((4, 3), np.nan)))
        assert math.isnan(finite_variance(np.array([])))
        assert finite_variance(np.array([[1.0, np.nan], [3.0, np.nan]])) == 1.0
    v = np.random.default_rng(1).normal(20.0, 3.0, 1000)
    v[::7] = np.nan
    assert finite_variance(v) == float(np.nanvar(v))     # the same number, bit for bit
