"""The wave-speed target of the identification: its gap on a model whose lambda_4 is
known, its residual, and its pull on a fit of synthetic runs."""

from __future__ import annotations

import math

import pytest

from arzsumo.identify import FitSettings, identify
from arzsumo.identify.data import IdentifyError
from arzsumo.identify.wave_target import INADMISSIBLE, WaveTarget
from arzsumo.model import Equilibrium, get_preset
from arzsumo.model.characteristic import linearize
from arzsumo.units import kmh_to_ms

from .conftest import OPTIONS, make_runs

PAPER = get_preset("paper_base").params
#: lambda_4 of the paper's base case at 110 HV/km and 95 AV/km (`arzsumo model`), m/s
LAMBDA_4 = float(kmh_to_ms(-68.381))


def test_the_gap_is_zero_at_the_models_own_wave_speed_and_relative_elsewhere():
    assert WaveTarget(LAMBDA_4, 0.110, 0.095).gap(PAPER) == pytest.approx(0.0, abs=1e-4)
    half = WaveTarget(2 * LAMBDA_4, 0.110, 0.095)
    assert half.gap(PAPER) == pytest.approx(0.5, abs=1e-4)
    assert half.residual(PAPER, 400) == pytest.approx(20 * 0.5, abs=1e-3)
    assert WaveTarget(LAMBDA_4, 0.110, 0.095, weight=0).residual(PAPER, 400) == 0.0


def test_an_equilibrium_beyond_the_jam_is_charged_the_fixed_penalty():
    beyond = WaveTarget(LAMBDA_4, 0.5, 0.5)
    assert math.isnan(beyond.lambda_4(PAPER)) and beyond.gap(PAPER) == INADMISSIBLE


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"speed": 3.0, "rho_h": 0.1, "rho_a": 0.1}, "wave speed = 3.0 is not allowed"),
    ({"speed": -3.0, "rho_h": -0.1, "rho_a": 0.1}, "rho_h = -0.1 is not allowed"),
    ({"speed": -3.0, "rho_h": 0.1, "rho_a": 0.1, "weight": -1}, "wave weight = -1"),
])
def test_bad_targets_are_refused(kwargs, message):
    with pytest.raises(IdentifyError, match=message):
        WaveTarget(**kwargs)


def test_the_target_pulls_the_fit_towards_the_wave_speed(truth):
    runs = make_runs(truth, noise=0.02, horizon=90.0)
    eq = (0.09, 0.05)                          # the middle run's operating point
    true_lam = float(linearize(Equilibrium(truth, *eq)).eigenvalues[3])
    target = WaveTarget(1.5 * true_lam, *eq, weight=3.0)
    settings = FitSettings(max_nfev=15)
    which = ("v_free_h", "v_free_a", "gamma_h", "gamma_a")
    plain = identify(runs, truth, which=which, options=OPTIONS, settings=settings)
    pulled = identify(runs, truth, which=which, options=OPTIONS, settings=settings,
                      wave_target=target)
    assert abs(target.gap(pulled.params)) < abs(target.gap(plain.params)) - 0.05
    assert pulled.cost > plain.cost                     # paid for with the replay's error
