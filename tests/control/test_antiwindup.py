"""Anti-windup: controllers with state see the U applied and the actuator's range."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import Controller
from arzsumo.control.etc import EventTriggered, u_bar_range
from arzsumo.control.kernels import solve_kernels
from arzsumo.control.observer import ObserverEtc

BOUND = 0.05          # veh/s: |U| <= BOUND, far below the law's U in these runs


@pytest.fixture(scope="module")
def kernels50(lin):
    return solve_kernels(lin.system, 50)


def _states(lin, kernels, n=60):
    """Scaled Riemann states whose law stays in about [-0.38, -0.13] veh/s (saturated)."""
    shape = (lin.system.n + 1, kernels.x.size)
    w0 = 10.0 * np.sin(np.linspace(0, 3, kernels.x.size))[None, :] * np.ones(shape)
    return [(1 + 0.5 * math.sin(i / 5)) * w0 for i in range(n)]


def _run_etc(lin, kernels, told: bool, bound: float = BOUND) -> EventTriggered:
    ctrl = EventTriggered(lin, kernels)
    ctrl.reset()
    for i, w in enumerate(_states(lin, kernels)):
        u = ctrl.check_riemann(float(i), w) / lin.u_bar_per_u
        if told:
            ctrl.applied(min(max(u, -bound), bound), -bound, bound)
    return ctrl


def test_saturated_etc_does_not_trigger_on_changes_that_cannot_arrive(lin, kernels50):
    off, on = _run_etc(lin, kernels50, False), _run_etc(lin, kernels50, True)
    law = np.asarray(on.log.u_continuous)
    assert law.max() < -BOUND                               # beyond the bound throughout
    assert off.log.triggers >= 40                           # raw d: events nearly every check
    assert on.log.triggers == 1                             # projected d = 0: only t_0
    assert np.allclose(on.log.extra["d"][1:], 0.0)


def test_a_range_that_never_binds_changes_nothing(lin, kernels50):
    off, wide = _run_etc(lin, kernels50, False), _run_etc(lin, kernels50, True, bound=10.0)
    assert wide.log.triggered == off.log.triggered
    assert wide.log.u_applied == off.log.u_applied and wide.log.extra == off.log.extra


def test_u_bar_range_orders_the_scaled_bounds():
    assert u_bar_range(-1.0, 2.0, 3.0) == (-3.0, 6.0)
    assert u_bar_range(-1.0, 2.0, -3.0) == (-6.0, 3.0)
    assert u_bar_range(-math.inf, math.inf, -2.0) == (-math.inf, math.inf)


def test_observer_integrates_with_the_applied_u(lin, kernels50):
    ys = [0.3 * math.sin(i / 4) for i in range(20)]

    def run(told) -> ObserverEtc:
        obs = ObserverEtc(lin, kernels50)
        obs.reset()
        for i, y in enumerate(ys):
            u_bar = obs.check_measurement(float(i), y)
            if told is not None:
                obs.applied(told(u_bar / lin.u_bar_per_u))
        return obs

    plain, same, zero = run(None), run(lambda u: u), run(lambda u: 0.0)
    assert np.abs(plain.log.u_continuous).max() > 0            # the law did command
    np.testing.assert_allclose(same.observer.estimate, plain.observer.estimate, atol=1e-12)
    assert np.abs(zero.observer.estimate - plain.observer.estimate).max() > 1e-6


def test_backstepping_is_static_and_keeps_the_default_hook(lin, kernels50):
    assert Backstepping.applied is Controller.applied
