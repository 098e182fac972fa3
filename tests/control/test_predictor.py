"""Delay predictor: linear transport along characteristics against the linear plant."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.control.plant import LinearPlant
from arzsumo.control.predictor import committed, held, predict_riemann
from arzsumo.errors import ModelError

from .conftest import run_norms

N = 200


def _initial(lin, x):
    """A smooth state with bumps in every variable, consistent with w+(0) = Q w-(0)."""
    s = lin.system
    L = s.length
    w = np.vstack([0.3 * np.sin(np.pi * (k + 1) * x / L) + 0.2 * np.cos(2 * np.pi * x / L)
                   for k in range(s.n + 1)])
    w[: s.n, 0] = s.Q * w[s.n, 0]
    w[s.n, -1] = s.R @ w[: s.n, -1]
    return w


def _u_bar(t):
    return 0.2 * np.sin(2 * np.pi * np.asarray(t) / 25.0)


@pytest.mark.parametrize("delay", [4.0, 12.0])
def test_prediction_matches_the_plant_theta_later(lin, delay):
    plant = LinearPlant(lin.system, N)
    w0 = _initial(lin, plant.x)
    plant.reset(w0)
    while plant.t < delay - 1e-9:
        plant.step(lambda t, w: float(_u_bar(t)))
    truth = plant.state
    pred = predict_riemann(lin.system, plant.x, w0, plant.t, lambda s: _u_bar(s))
    err_pred = np.sqrt(np.mean((pred - truth) ** 2))
    err_now = np.sqrt(np.mean((w0 - truth) ** 2))       # no prediction: the state now
    assert err_pred < 0.1 * err_now
    # the boundary value the law sees: w-(L) and the w+ it reflects
    assert abs(pred[-1, -1] - truth[-1, -1]) < 0.05 * abs(w0[-1, -1] - truth[-1, -1]) + 1e-3


def test_held_committed_and_zero_delay(lin):
    x = np.linspace(0, lin.system.length, N + 1)
    w0 = _initial(lin, x)
    np.testing.assert_allclose(predict_riemann(lin.system, x, w0, 0.0), w0, atol=1e-12)
    ahead = committed(np.array([0.0, 5.0, 9.0]), np.array([1.0, 2.0, 3.0]), now=10.0,
                      delay=8.0)
    np.testing.assert_array_equal(ahead(np.array([0.5, 2.0, 3.5, 8.0])), [1.0, 1.0, 2.0, 3.0])
    assert held(0.7)(np.array([1.0, 2.0])).tolist() == [0.7, 0.7]
    with pytest.raises(ModelError, match="delay"):
        predict_riemann(lin.system, x, w0, 1e4)
    with pytest.raises(ModelError, match="w_bar"):
        predict_riemann(lin.system, x, w0[:, :-1], 1.0)


def _closed_loop(lin, delay, predict, t_end):
    """Backstepping (control_law) on the linear plant with its input delayed by ``delay``
    s; with ``predict`` the law acts on the predicted state. Returns the L2 norms."""
    from arzsumo.control.kernels import solve_kernels
    from arzsumo.control.transform import BacksteppingLaw

    s = lin.system
    law = BacksteppingLaw(s, solve_kernels(s, 100))
    plant = LinearPlant(s, 100)
    plant.reset(_initial(lin, plant.x))
    issued_t, issued_u = [], []

    def u_bar(t, w):
        if predict:
            w = predict_riemann(s, plant.x, w, delay,
                                committed(np.array(issued_t), np.array(issued_u), t, delay))
        issued_t.append(t)
        issued_u.append(law.u_bar(w))
        k = np.searchsorted(issued_t, t - delay, side="right") - 1
        return issued_u[k] if k >= 0 else 0.0

    return run_norms(plant, t_end, u_bar)


def test_predictor_restores_convergence_under_one_cycle_of_delay(lin):
    """A 6 s input delay (one meter cycle) makes the continuous law diverge on the linear
    plant (paper_base); on the predicted state it converges again."""
    t_end = 2 * lin.system.t_f
    plain = _closed_loop(lin, 6.0, False, t_end)
    predicted = _closed_loop(lin, 6.0, True, t_end)
    assert plain[-1] > 2 * plain[0]
    assert predicted[-1] < 0.01 * predicted[0]
