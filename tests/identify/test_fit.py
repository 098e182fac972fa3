"""Synthetic recovery: data from the twin with known parameters, 2 % noise, 8 parameters.

Measured (seeds 0, 10, 20, 30; 3 runs of 120 s, 30 cells): relative errors below 1 % for
the fundamental-diagram parameters and below 2.5 % for tau; |error| / sigma at most 2.54.
The tolerances below leave a margin (5 % and 15 %, 3 sigma).
"""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.identify import FitSettings, identify, validate
from arzsumo.identify.synthetic import SyntheticRun, synthetic_data

from .conftest import OPTIONS, make_runs

NOISE = 0.02


@pytest.fixture(scope="module")
def fit(truth, guess):
    runs = make_runs(truth, noise=NOISE, seed=0)
    return identify(runs, guess, options=OPTIONS)


def test_parameters_are_recovered(fit, truth, guess):
    rel_guess = {n: abs(getattr(guess, n) / getattr(truth, n) - 1) for n in fit.which}
    assert min(rel_guess.values()) > 0.18 and max(rel_guess.values()) < 0.4
    for name, value in zip(fit.which, fit.values, strict=True):
        rel = abs(value / getattr(truth, name) - 1)
        assert rel < (0.15 if name.startswith("tau") else 0.05), (name, value)
    assert fit.params.tau_h == fit.values[fit.which.index("tau_h")]


def test_truth_lies_within_three_sigma(fit, truth):
    true = np.array([getattr(truth, n) for n in fit.which])
    assert np.all(fit.sigma > 0) and not fit.at_bound.any()
    z = (fit.values - true) / fit.sigma
    assert np.max(np.abs(z)) < 3.0, dict(zip(fit.which, z.round(2), strict=True))
    # and the sigmas are tight: well under the tolerances of the recovery test
    assert np.max(fit.sigma / true) < 0.03


def test_training_error_is_the_noise_and_the_cost_is_reported(fit):
    np.testing.assert_allclose(fit.training.pooled, NOISE, rtol=0.1)
    assert fit.success and fit.nfev >= 2 and fit.evaluations >= fit.nfev * 2
    assert fit.residuals == 3 * 24 * 4 * 30
    assert fit.wall_time > 0 and fit.failures >= 1           # the guess leaves the domain
    corr = fit.correlation
    np.testing.assert_allclose(np.diag(corr), 1.0)
    assert np.all(np.abs(corr) <= 1.0 + 1e-9)


def test_held_out_run_is_predicted_at_the_noise_level(fit, truth, guess):
    held = synthetic_data(truth, SyntheticRun(0.1, 0.04, wave=0.1, periods=3.0,
                                              inlet_period=80.0), horizon=120.0,
                          period=5.0, options=OPTIONS, noise=NOISE, seed=99, name="held")
    at_fit = validate(fit.params, [held], OPTIONS)
    at_truth = validate(truth, [held], OPTIONS)
    at_guess = validate(guess, [held], OPTIONS)
    assert at_truth.pooled.max() < 1.2 * NOISE
    assert at_fit.pooled.max() < 1.2 * NOISE
    assert at_guess.pooled.min() > 5 * NOISE
    assert at_fit.names == ("held",) and at_fit.rmse.shape == (1, 4)


def test_bootstrap_over_runs_is_seeded(truth):
    """tau_h on noisy runs: bootstrap refits scatter around the truth, reproducibly."""
    runs = make_runs(truth, noise=NOISE, seed=5, horizon=60.0)[1:]
    start = truth.with_(tau_h=26.0)
    settings = FitSettings(bootstrap=3, seed=1)
    one = identify(runs, start, which=("tau_h",), options=OPTIONS, settings=settings)
    two = identify(runs, start, which=("tau_h",), options=OPTIONS, settings=settings)
    assert one.bootstrap is not None and one.bootstrap.shape == (3, 1)
    np.testing.assert_array_equal(one.bootstrap, two.bootstrap)
    np.testing.assert_allclose(one.bootstrap, 20.0, rtol=0.15)   # 60 s runs: 17.9-20.1 s
    sigma = float(np.std(one.bootstrap[:, 0], ddof=1))     # the refits' sample spread
    assert sigma > 0 and one.bootstrap_sigma is not None
    assert one.bootstrap_sigma[0] == pytest.approx(sigma, rel=1e-12)
