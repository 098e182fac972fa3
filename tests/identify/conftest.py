"""Fixtures of the identification tests: true parameters, a perturbed guess, synthetic runs."""

from __future__ import annotations

import pytest

from arzsumo.identify import ReplayOptions
from arzsumo.identify.synthetic import SyntheticRun, synthetic_data
from arzsumo.model import ModelParameters

#: Twin grid of the tests: 30 cells of 33 m (cheap; the generator uses the same grid).
OPTIONS = ReplayOptions(cells=30)
#: Three operating points, AO* about 0.29, 0.45 and 0.59, with different excitations.
RUNS = (SyntheticRun(0.06, 0.03), SyntheticRun(0.09, 0.05, inlet_period=60.0),
        SyntheticRun(0.11, 0.07, outflow_period=50.0))


@pytest.fixture(scope="package")
def truth():
    """SUMO-like parameters (79 / 61 km/h, AO_max 0.80 / 0.78, tau 20 / 40 s)."""
    return ModelParameters(v_free_h=22.0, v_free_a=17.0, ao_max_h=0.8, ao_max_a=0.78,
                           gamma_h=1.6, gamma_a=2.2, tau_h=20.0, tau_a=40.0)


@pytest.fixture(scope="package")
def guess(truth):
    """Every fitted parameter 19 to 35 % off the truth (AO_max_a below the data's AO)."""
    return truth.with_(v_free_h=22.0 * 1.25, v_free_a=17.0 * 0.75, ao_max_h=0.95,
                       ao_max_a=0.62, gamma_h=1.6 * 1.3, gamma_a=2.2 * 0.7, tau_h=28.0,
                       tau_a=26.0)


def make_runs(params, noise=0.0, seed=0, horizon=120.0):
    return [synthetic_data(params, run, horizon=horizon, period=5.0, options=OPTIONS,
                           noise=noise, seed=seed + i, name=f"op{i}")
            for i, run in enumerate(RUNS)]
