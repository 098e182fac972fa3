"""Performance indices of section 5 and the run bookkeeping."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.control.events import release_time
from arzsumo.pde.metrics import (
    B_FUEL,
    acceleration,
    deviation_norm,
    events,
    performance,
    relative_change,
)


def _uniform(eq, n_t=11, n_x=50, T=100.0):
    t = np.linspace(0.0, T, n_t)
    x = (np.arange(n_x) + 0.5) * eq.params.length / n_x
    fields = np.broadcast_to(np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])[None, :, None],
                             (n_t, 4, n_x)).copy()
    return t, x, fields


def test_indices_at_equilibrium_in_closed_form(base_eq):
    eq = base_eq
    t, x, fields = _uniform(eq)
    perf = performance(eq.params, t, x, fields)
    T, L = 100.0, eq.params.length
    assert pytest.approx(eq.rho_h * L * T) == perf.h.J_TTT
    assert pytest.approx(eq.q_a * L * T) == perf.a.TMT
    assert perf.h.total_delay == pytest.approx(eq.rho_h * L * T * (1 - eq.v_h / eq.params.v_free_h))
    assert perf.total.J_discom == 0.0
    b0, b1, _, b3 = B_FUEL
    fuel_h = (b0 + b1 * eq.v_h + b3 * eq.v_h ** 3) * eq.rho_h * L * T
    assert perf.h.J_fuel == pytest.approx(fuel_h)
    assert pytest.approx(perf.h.J_TTT + perf.a.J_TTT) == perf.total.J_TTT


def test_acceleration_is_material_derivative():
    t = np.linspace(0, 10, 101)
    x = np.linspace(0, 100, 201)
    v = 2.0 + 0.1 * t[:, None] + 0.0 * x[None, :]          # uniform speed-up: a = 0.1
    np.testing.assert_allclose(acceleration(t, x, v), 0.1, atol=1e-12)
    v = 1.0 + 0.01 * x[None, :] + 0.0 * t[:, None]         # steady: a = v v_x
    np.testing.assert_allclose(acceleration(t, x, v), v * 0.01, rtol=1e-9)


def test_relative_change_in_percent(base_eq):
    t, x, fields = _uniform(base_eq)
    base = performance(base_eq.params, t, x, fields)
    fields2 = fields.copy()
    fields2[:, 0] *= 0.9
    run = performance(base_eq.params, t, x, fields2)
    rel = relative_change(run, base)
    assert rel["h"]["J_TTT"] == pytest.approx(-10.0)
    assert rel["a"]["J_TTT"] == pytest.approx(0.0)


def test_deviation_norm_relative_l2(base_eq):
    _t, x, fields = _uniform(base_eq, n_x=1000)
    assert np.all(deviation_norm(base_eq, x, fields) == 0)
    fields[:, 0] *= 1.0 + 0.1 * np.sin(2 * np.pi * x / x[-1])[None, :]
    assert deviation_norm(base_eq, x, fields)[0] == pytest.approx(0.1 / np.sqrt(2), rel=1e-2)


def test_events_and_release_time():
    ct = np.arange(10.0)
    u = np.array([0, 0, 1, 1, 1, 2, 2, 2, 2, 3], float)
    mask = events(ct, u, None)
    assert mask.tolist() == [False, False, True, False, False, True, False, False, False, True]
    assert release_time(ct, mask, 10.0) == pytest.approx(7.0)      # 10 s - 3 updates
    logged = [True] * 10                                             # backstepping-like
    assert release_time(ct, events(ct, u, logged), 10.0) == 0.0
