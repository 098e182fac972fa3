"""The replay twin reproduces its generator and honours the measured boundary data."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.identify import ReplayData, ReplayOptions, replay, run_replay
from arzsumo.identify.objective import DEFAULT_WHICH, Objective, ParameterSpace
from arzsumo.model import equilibrium_from_densities

from .conftest import OPTIONS, make_runs


def test_residual_at_the_truth_is_zero_without_noise(truth):
    """Same grid, same boundary data: the replay is the generator, to the last bit."""
    runs = make_runs(truth)
    space = ParameterSpace.make(truth, DEFAULT_WHICH)
    obj = Objective(space, runs, np.ones(4), OPTIONS, 10.0)
    r = obj(np.zeros(len(DEFAULT_WHICH)))
    assert r.size == sum(int(d.mask.sum()) for d in runs) == 3 * 24 * 4 * 30
    assert np.max(np.abs(r)) < 1e-12
    assert obj.failures == 0 and obj.evaluations == 1
    # the data really move: a stop-and-go wave and its boundary excitation
    spread = [np.ptp(d.fields[:, 1]) / d.scale[1] for d in runs]
    assert min(spread) > 0.3


def test_residual_grows_away_from_the_truth(truth):
    runs = make_runs(truth)[:1]
    space = ParameterSpace.make(truth, ("tau_h",))
    obj = Objective(space, runs, np.ones(4), OPTIONS, 10.0)
    costs = [float(obj(np.array([z])) @ obj(np.array([z]))) for z in (0.0, 0.05, 0.2)]
    assert costs[0] < 1e-24 < costs[1] < costs[2]


def test_equilibrium_is_replayed_exactly_on_another_grid(truth):
    """A uniform equilibrium with inlet and outflow at it stays put, at SUMO-like positions."""
    eq = equilibrium_from_densities(truth, 0.1, 0.06)
    star = np.array([eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])
    x = np.arange(20) * 50.0 + 25.0                         # 20 cells of 50 m
    t = np.arange(1, 31) * 2.0
    data = ReplayData.from_arrays(t, x, np.broadcast_to(star[None, :, None], (30, 4, 20)),
                                  np.broadcast_to(star[:, None], (4, 20)),
                                  np.broadcast_to(star, (30, 4)), np.full(30, eq.q))
    pred = replay(truth, data, ReplayOptions(cells=40))
    np.testing.assert_allclose(pred, data.fields, rtol=1e-12)


def test_outlet_carries_the_measured_outflow(truth):
    """q* + U = outflow_k: the vehicles leaving are the sum of outflow_k times the period."""
    data = make_runs(truth)[2]                               # congested operating point
    run = run_replay(truth, data, OPTIONS)
    assert run.stopped is None and run.outlet_limited == 0.0
    expected = float(np.sum(data.outflow * np.diff(np.concatenate([[0.0], data.t]))))
    assert run.vehicles_out == pytest.approx(expected, rel=1e-12)


def test_twin_leaving_the_domain_is_reported_not_raised(truth):
    """AO_max far below the data's AO: the replay stops, says where, and returns NaN fields."""
    data = make_runs(truth)[2]
    run = run_replay(truth.with_(ao_max_h=0.3, ao_max_a=0.3), data, OPTIONS)
    assert run.stopped is not None and "AO" in run.reason
    assert np.isnan(run.fields[-1]).all()
    space = ParameterSpace.make(truth, ("ao_max_a",))
    obj = Objective(space, [data], np.ones(4), OPTIONS, 10.0)
    r = obj(np.array([np.log(0.3 / 0.78)]))
    assert obj.failures == 1 and np.isfinite(r).all() and np.max(r) == 10.0
