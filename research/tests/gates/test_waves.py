"""Gate 2, the waves, on fields v(x, t) = f(x - c t) with a known speed c."""

import json

import numpy as np
import pytest
from arzsumo_studies.gates import (
    PremiseError,
    model_wave_gate,
    wave_gate,
    wave_speed,
)
from hypothesis import given, settings
from hypothesis import strategies as st

DT, DX = 1.0, 50.0                        # the control grid: 1 s, 50 m cells


def _carried(c: float, seed: int, noise: float = 0.1, periods: int = 1800) -> np.ndarray:
    """A random profile f carried at c (m/s): v(x, t) = f(t - x / c) on 20 places, on a
    mean profile falling towards the meter, with vehicle noise and an empty stretch."""
    rng = np.random.default_rng(seed)
    t = np.arange(periods)[:, None] * DT
    x = (np.arange(20)[None, :] + 0.5) * DX
    base = np.cumsum(rng.normal(0.0, 0.3, 8000))
    f = 8.0 - 0.002 * x + np.interp(t - x / c + 3000.0, np.arange(8000.0), base)
    f += rng.normal(0.0, noise, f.shape)
    f[200:215, 4] = np.nan
    return f


@pytest.mark.parametrize("c", [-4.0, -3.1, -6.9])       # -14, -11 and -25 km/h
def test_an_upstream_wave_passes_and_its_speed_is_recovered(c):
    g = wave_gate(_carried(c, 1), DT, DX, "hv")
    assert g.name == "waves[hv]" and g.passed
    assert g.detail["direction"] == "upstream"
    assert abs(g.value - c) / abs(c) < 0.05
    assert g.detail["r2"] > 0.99 and g.detail["n_used"] == 4
    assert json.loads(json.dumps(g.as_dict()))["detail"]["direction"] == "upstream"
    assert g.detail["lags_s"] == pytest.approx([d / c for d in (100, 200, 300, 400)], abs=1.0)


@pytest.mark.parametrize("c", [4.0, 16.7])                # 14 and 60 km/h downstream
def test_a_downstream_wave_fails(c):
    g = wave_gate(_carried(c, 2), DT, DX, "av")
    assert not g.passed and g.detail["direction"] == "downstream"
    assert g.value == pytest.approx(c, rel=0.05) and g.value > 0


@settings(max_examples=15, deadline=None)
@given(c=st.floats(-9.0, -2.5), seed=st.integers(0, 2**16))
def test_any_upstream_speed_in_range_is_recovered_within_5_percent(c, seed):
    w = wave_speed(_carried(c, seed, periods=1200), DT, DX)
    assert w.n_used >= 3
    assert abs(w.speed - c) / abs(c) < 0.05 and w.speed < 0


def test_noise_without_a_wave_is_unresolved_and_fails():
    rng = np.random.default_rng(3)
    g = wave_gate(rng.normal(size=(1200, 20)), DT, DX)
    assert not g.passed and g.detail["direction"] == "unresolved"
    assert g.detail["n_used"] < 3 and np.isnan(g.value)


def test_a_signal_everywhere_at_once_has_no_linear_lag_and_fails():
    rng = np.random.default_rng(4)
    common = np.repeat(np.cumsum(rng.normal(size=(1200, 1)), axis=0), 20, axis=1)
    g = wave_gate(common + rng.normal(0.0, 0.1, common.shape), DT, DX)
    assert g.detail["lags_s"] == pytest.approx([0.0] * 4, abs=1.0)
    assert not g.detail["linear"] and not g.passed


def test_the_field_must_be_periods_by_places():
    with pytest.raises(ValueError, match="field = \\(5, 20\\) is not allowed"):
        wave_speed(np.zeros((5, 20)), DT, DX)


@pytest.mark.parametrize(("lambda_4", "measured", "ratio", "passed"), [
    (-4.4, -4.0, 1.1, True),
    (-3.2, -4.0, 0.8, True),
    (-6.0, -4.0, 1.5, False),          # the model's waves 50 % faster than SUMO's
    (-2.8, -4.0, 0.7, False),
    (4.0, -4.0, 1.0, False),           # the model says free flow
    (-4.0, 4.0, 1.0, False),           # SUMO's waves travel downstream
])
def test_the_model_gate_compares_lambda_4_with_the_measured_speed(lambda_4, measured,
                                                                  ratio, passed):
    g = model_wave_gate(lambda_4, measured, "hv")
    assert g.name == "model_wave[hv]"
    assert g.value == pytest.approx(ratio) and g.passed is passed


def test_the_model_gate_fails_on_an_unmeasured_speed():
    g = model_wave_gate(-4.0, float("nan"))
    assert np.isnan(g.value) and not g.passed
    with pytest.raises(PremiseError, match="lambda_4 = nan"):
        model_wave_gate(float("nan"), -4.0)
