"""Gate 3, instability: amplification upstream and the paired pulse test, on synthetic
fields with known answers."""

import json
import math

import numpy as np
import pytest
from arzsumo_studies.gates import (
    PremiseError,
    amplification_gate,
    deviation_norm,
    pulse_gate,
    pulse_response,
    round_trip_time,
)
from arzsumo_studies.gates.instability import smoothed
from hypothesis import given, settings
from hypothesis import strategies as st

L, DX, N = 1000.0, 50.0, 20
X = (np.arange(N) + 0.5) * DX
T = np.arange(1801.0)                           # 30 min at 1 s
T0 = 300.0                                      # the meter held red from here
ROUND_TRIP = round_trip_time(L, 10.0, -3.0)     # 100 s down, 333 s back up
SHAPE = np.sin(np.pi * X / L)                   # the pulse's shape along x


def test_the_round_trip_is_down_at_v_and_back_at_lambda():
    assert math.isclose(ROUND_TRIP, 100.0 + 1000.0 / 3.0)
    assert round_trip_time(L, 10.0, 3.0) == ROUND_TRIP     # lambda's sign ignored
    with pytest.raises(PremiseError, match=r"v_down = 0\.0 is not allowed"):
        round_trip_time(L, 0.0, -3.0)
    with pytest.raises(PremiseError, match=r"lambda_up = 0\.0 is not allowed"):
        round_trip_time(L, 10.0, 0.0)


def _blocks(growth_per_m: float, seed: int = 0) -> np.ndarray:
    """(T, N) speeds: a 3 min wave travelling upstream whose amplitude is
    exp(growth (L - x)), about a profile, with noise."""
    rng = np.random.default_rng(seed)
    amp = np.exp(growth_per_m * (L - X))
    wave = amp * np.sin(2 * np.pi * (T[:, None] + X / 4.0) / 180.0)
    return 8.0 - 0.002 * X + wave + rng.normal(0.0, 0.01, (T.size, N))


def test_an_amplitude_growing_upstream_is_amplified_and_passes():
    g = amplification_gate(_blocks(1.5e-3), X, L, "hv")
    amp = np.exp(1.5e-3 * (L - X))
    expected = (amp[0] + amp[1]) / (amp[-2] + amp[-1])            # about 4.0
    assert g.name == "amplification[hv]" and g.passed
    assert g.value == pytest.approx(expected, rel=0.01)
    assert g.detail["growth_per_m"] == pytest.approx(1.5e-3, rel=0.02)
    assert g.detail["amplitude_ms"][0] == pytest.approx(amp[0] / math.sqrt(2), rel=0.01)


def test_an_amplitude_decaying_upstream_fails():
    g = amplification_gate(_blocks(-1.0e-3), X, L, "av")
    assert not g.passed
    assert g.value == pytest.approx(math.exp(-1.0e-3 * 925.0), rel=0.03)
    assert g.detail["growth_per_m"] == pytest.approx(-1.0e-3, rel=0.02)


def _fields(amplitude, floor_sd: float = 0.0, seed: int = 1):
    """Baseline and pulse speed fields of two classes; the pulse run deviates by
    amplitude(t) sin(pi x / L) (0 before T0), plus decorrelation noise of sd floor_sd."""
    rng = np.random.default_rng(seed)
    a = np.where(T >= T0, amplitude(np.maximum(T - T0, 0.0)), 0.0)[:, None]
    base = {c: 8.0 + np.sin(2 * np.pi * (T[:, None] + X / 4.0) / 180.0) for c in ("h", "a")}
    pulse = {c: b + a * SHAPE + floor_sd * rng.normal(size=b.shape) * (T[:, None] >= T0)
             for c, b in base.items()}
    return base, pulse


def _rise(s: np.ndarray) -> np.ndarray:
    return np.minimum(s / 25.0, 1.0)            # 25 s of red builds the perturbation


def test_a_growing_pulse_passes():
    base, pulse = _fields(lambda s: _rise(s) * np.exp(s / 600.0))
    g = pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP)
    window = 2 * ROUND_TRIP
    assert g.name == "pulse" and g.passed and math.isnan(g.value)
    assert g.threshold == pytest.approx(window)
    total = g.detail["total"]
    assert total["peak_time_s"] == pytest.approx(math.floor(window), abs=1.0)
    # D of one class: a sqrt(sum sin^2 dx) = a sqrt(L / 2); the total holds two classes
    assert total["peak"] == pytest.approx(math.exp(866 / 600) * math.sqrt(L), rel=0.01)
    assert g.detail["h"]["peak"] == pytest.approx(total["peak"] / math.sqrt(2))
    assert json.loads(json.dumps(g.as_dict()))["detail"]["total"]["decayed"] is False


def test_a_persisting_pulse_passes():
    base, pulse = _fields(lambda s: _rise(s) * (1.0 + 0.3 * np.sin(s / 40.0)))
    g = pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP)
    assert g.passed and not g.detail["total"]["decayed"]


def test_a_decaying_pulse_fails_and_its_decay_time_is_measured():
    base, pulse = _fields(lambda s: _rise(s) * np.exp(-np.maximum(s - 25.0, 0.0) / 60.0))
    g = pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP)
    assert not g.passed
    assert g.detail["total"]["peak_time_s"] == pytest.approx(25.0)
    assert g.value == pytest.approx(25.0 + 60.0, abs=1.0)          # one e-folding
    assert g.detail["h"]["decay_time_s"] == pytest.approx(85.0, abs=1.0)


def test_a_pulse_decaying_into_noise_fails_only_once_the_floor_is_given():
    amp = lambda s: 0.6 * _rise(s) * np.exp(-np.maximum(s - 25.0, 0.0) / 60.0)  # noqa: E731
    base, pulse = _fields(amp, floor_sd=0.8)
    # decorrelated runs: D of a class settles at sd sqrt(L), above 1/e of the peak
    floor = 0.8 * math.sqrt(L)
    assert pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP).passed
    floors = {"h": floor, "a": floor, "total": floor * math.sqrt(2)}
    g = pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP, floor=floors, smooth_s=30.0)
    assert not g.passed and 25.0 < g.value < 2 * ROUND_TRIP   # decays within the window
    # no pulse at all: the noise's own ups and downs decay at once; under a floor above
    # the noise D never rises over it, and nothing passes
    base, pulse = _fields(lambda s: 0.0 * s, floor_sd=0.8)
    assert not pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP, floor=floors,
                          smooth_s=30.0).passed
    quiet = pulse_gate(T, base, pulse, DX, T0, ROUND_TRIP, floor={"total": 2 * floor},
                       smooth_s=30.0)
    assert not quiet.detail["total"]["detectable"] and not quiet.passed


def test_smoothing_is_a_centred_moving_mean_that_skips_nan():
    v = np.array([0.0, 3.0, np.nan, 3.0, 6.0, 9.0])
    assert smoothed(np.arange(6.0), v, 3.0)[1:5] == pytest.approx([1.5, 3.0, 4.5, 6.0])
    assert smoothed(np.arange(6.0), v, 1.0) is v or np.array_equal(
        smoothed(np.arange(6.0), v, 1.0), v, equal_nan=True)


@settings(max_examples=30, deadline=None)
@given(tau=st.floats(5.0, 1400.0))      # the record ends 1500 s after T0
def test_an_exponential_decay_takes_one_time_constant_to_fall_to_1_over_e(tau):
    norm = np.exp(-np.maximum(T - T0, 0.0) / tau)
    out = pulse_response(T, norm, T0, 2 * ROUND_TRIP, math.exp(-1.0))
    assert out["peak_time_s"] == 0.0
    assert out["decay_time_s"] == pytest.approx(tau, abs=1.0)
    assert out["decayed"] is (out["decay_time_s"] <= 2 * ROUND_TRIP)


def test_the_norm_is_the_l2_norm_over_x_and_skips_unobserved_cells():
    base = np.zeros((3, 4))
    pulse = np.array([[1.0, 1.0, 1.0, 1.0], [2.0, np.nan, 2.0, 2.0], [np.nan] * 4])
    d = deviation_norm(base, pulse, 50.0)
    assert d[:2] == pytest.approx([math.sqrt(4 * 50.0), math.sqrt(4 * 4 * 50.0)])
    assert np.isnan(d[2])


def test_bad_pulse_inputs_are_refused():
    base, pulse = _fields(_rise)
    with pytest.raises(PremiseError, match=r"t = 'ending at 1000\.0 s' is not allowed"):
        pulse_gate(T[:1001], {c: b[:1001] for c, b in base.items()},
                   {c: p[:1001] for c, p in pulse.items()}, DX, T0, ROUND_TRIP)
    with pytest.raises(PremiseError, match="the classes of the baseline"):
        pulse_gate(T, base, {"h": pulse["h"]}, DX, T0, ROUND_TRIP)
    with pytest.raises(PremiseError, match="baseline's shape"):
        deviation_norm(np.zeros((3, 4)), np.zeros((3, 5)), DX)


def _seeds(response, n: int, noise: float, seed: int = 0):
    """n seeds of (baseline, pulse) fields: pulse = baseline + response + noise, the
    noise independent per seed (the runs' decorrelation after the pulse)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 601.0)
    shape = (t.size, 20)
    base, puls = [], []
    for _ in range(n):
        b = 10.0 + rng.normal(0.0, 1.0, shape)
        base.append({"hv": b})
        puls.append({"hv": b + response(t)[:, None] + rng.normal(0.0, noise, shape)})
    floor = noise * math.sqrt(20 * 50.0)       # D of two runs that differ by the noise only
    return t, base, puls, [{"hv": floor, "total": floor}] * n


@pytest.mark.parametrize(("response", "persists"), [
    (lambda t: 2.0 * np.ones_like(t), True),         # the pulse's effect stays
    (lambda t: 2.0 * np.exp(-t / 20.0), False),      # it decays in 20 s
])
def test_the_mean_response_over_seeds_reads_what_one_noisy_seed_cannot(response, persists):
    from arzsumo_studies.gates import mean_response_gate

    t, base, puls, floors = _seeds(response, 16, 3.0)
    mean = mean_response_gate(t, base, puls, 50.0, 0.0, 100.0, floors, smooth_s=30.0)
    assert mean.name == "pulse_mean" and mean.detail["seeds"] == 16
    assert mean.passed is persists
    if not persists:
        assert mean.value < 100.0            # decayed within a round trip
    # one seed: the response (norm 63) is below the noise's floor (95), nothing to read
    one = pulse_gate(t, base[0], puls[0], 50.0, 0.0, 100.0, floors[0], smooth_s=30.0)
    assert one.detail["total"]["peak"] < 1.5 * floors[0]["total"]


def test_the_mean_response_needs_two_seeds():
    from arzsumo_studies.gates import mean_response_gate

    t, base, puls, floors = _seeds(lambda t: np.zeros_like(t), 1, 1.0)
    with pytest.raises(PremiseError, match="two or more seeds"):
        mean_response_gate(t, base, puls, 50.0, 0.0, 100.0, floors)
