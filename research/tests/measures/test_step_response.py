"""FOPDT step-response fit: exact and noisy recovery of known K, theta, T."""

from __future__ import annotations

import numpy as np
import pytest
from arzsumo_studies.measures.step_response import StepData, fit_fopdt, fopdt_response

from arzsumo.errors import ArzsumoError

K, THETA, TAU = -0.9, 7.0, 12.0          # veh/s per unit, s, s
LEVEL = 1.25                             # veh/s at u = 0.5
SEQUENCE = [0.5, 0.2, 0.5, 0.8, 0.5]     # the staircase of the SUMO study
NOISE = 0.3                              # veh/s, Gaussian per 1 s bin


def _staircase(rng: np.random.Generator | None, hold: float = 100.0, pre: float = 60.0
               ) -> StepData:
    """Per-second flows of the staircase, with Gaussian noise when ``rng`` is given."""
    t0 = pre + hold * np.arange(len(SEQUENCE) - 1)
    du = np.diff(SEQUENCE)
    t = np.arange(1.0, t0[-1] + hold + 1)
    mean = LEVEL + sum(fopdt_response(t, 0.0, K, d, s, THETA, TAU, 1.0)
                       for s, d in zip(t0, du, strict=True))
    y = mean + rng.normal(0.0, NOISE, mean.size) if rng is not None else mean
    return StepData(t, y, tuple(t0), tuple(du))


def _single_steps(record: StepData, pre: float = 40.0) -> list[StepData]:
    """The staircase cut into one record per step (each with its own level)."""
    out = []
    for j, (t0, du) in enumerate(zip(record.t0, record.du, strict=True)):
        end = record.t0[j + 1] if j + 1 < len(record.t0) else np.inf
        keep = (record.t > t0 - pre) & (record.t <= end)
        out.append(StepData(record.t[keep], record.y[keep], t0, du))
    return out


def test_bin_mean_is_the_mean_of_point_values():
    t = np.array([95.0, 108.0, 109.5, 130.0])
    fine = np.linspace(-1, 0, 2001)
    want = [fopdt_response(ti + fine, 1.0, K, 0.3, 100.0, THETA, TAU).mean() for ti in t]
    got = fopdt_response(t, 1.0, K, 0.3, 100.0, THETA, TAU, bin_width=1.0)
    np.testing.assert_allclose(got, want, rtol=0, atol=2e-4)
    assert got[0] == 1.0 and got[3] < 1.0   # before the delay: level; later: K du < 0


@pytest.mark.parametrize("split", [False, True])
def test_exact_data_is_recovered_exactly(split):
    rec = _staircase(None)
    fit = fit_fopdt(_single_steps(rec) if split else [rec])
    # cut into single steps, each record starts 60 s after the step before: 1 % of that
    # step's response is still to come
    tol = 0.02 if split else 1e-6
    assert fit.gain == pytest.approx(K, abs=tol)
    assert fit.delay == pytest.approx(THETA, abs=10 * tol)
    assert fit.time_constant == pytest.approx(TAU, abs=10 * tol)
    assert fit.residual_sd < tol
    assert fit.y0[0] == pytest.approx(LEVEL, abs=tol)


def test_noisy_flows_recovered_within_three_sigma():
    recs = [_staircase(np.random.default_rng(s)) for s in range(6)]
    fit = fit_fopdt(recs)
    # tolerances a wrong fit fails: a point-sample model biases theta by 0.5 s; no
    # dead time puts T near 17 s; a wrong sign of K is off by 1.8
    for est, true, sig, tol in [(fit.gain, K, fit.sigma_gain, 0.1),
                                (fit.delay, THETA, fit.sigma_delay, 2.0),
                                (fit.time_constant, TAU, fit.sigma_time_constant, 4.0)]:
        assert abs(est - true) < 3 * sig and abs(est - true) < tol
    assert fit.residual_sd == pytest.approx(NOISE, rel=0.05)
    assert len(fit.y0) == 6 and fit.n_samples == 6 * 460


def test_sigmas_cover_the_error_over_noise_draws():
    """The Jacobian sigma of K is the scatter of K over noise draws (within 40 %)."""
    fits = [fit_fopdt([_staircase(np.random.default_rng(100 + s))]) for s in range(12)]
    k = np.array([f.gain for f in fits])
    sig = np.median([f.sigma_gain for f in fits])
    assert abs(k.mean() - K) < 3 * sig / np.sqrt(len(k))
    assert 0.6 < k.std(ddof=1) / sig < 1.4


def test_a_single_step_works_and_bad_input_is_refused():
    rec = _staircase(None)
    first = rec.t <= rec.t0[1]
    fit = fit_fopdt([StepData(rec.t[first], rec.y[first], rec.t0[0], rec.du[0])])
    assert fit.delay == pytest.approx(THETA, abs=1e-4)
    assert fit.gain == pytest.approx(K, abs=1e-6)
    with pytest.raises(ArzsumoError, match="du"):
        StepData(np.arange(10.0), np.ones(10), 5.0, 0.0)
    with pytest.raises(ArzsumoError, match="steps"):
        fit_fopdt([])
