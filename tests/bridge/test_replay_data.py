"""A SUMO run as identification data (:mod:`arzsumo.bridge.replay_data`): the identification's
replay twin, given that data, reproduces the bridge's replay twin of the run."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from arzsumo.bridge.boundary_data import (
    RHO_FLOOR,
    inlet_series,
    measured_state,
    outflow_series,
    smooth_step,
)
from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.replay_data import replay_data_of, replay_options_of
from arzsumo.bridge.session import prepare_run
from arzsumo.identify import run_replay
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.scenario import load_scenario

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
#: bit-identical in practice (same functions, same order of operations); the only
#: rounding that may differ is q* + (outflow - q*) with another q*, hence a tolerance
TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def run():
    """60 s of open loop after the scenario's warm-up (seed 5: no re-sync on legacy_default,
    the former default scenario; the test compares up to the first re-sync if any)."""
    return run_cosimulation(prepare_run(load_scenario(DEFAULT), controller="open",
                                        horizon=60.0, seed=5))


@pytest.mark.sumo
def test_the_data_is_the_run(run):
    data = replay_data_of(run)
    assert data.name == "seed 5" and data.periods == 60 == run.t.size
    np.testing.assert_array_equal(data.fields, run.micro)          # NaN where unobserved
    assert np.isfinite(data.initial).all() and data.initial[[0, 2]].min() >= RHO_FLOOR
    eq = run.equilibrium
    np.testing.assert_array_equal(data.scale, [eq.rho_h, eq.v_h, eq.rho_a, eq.v_a])
    total = run.periods["outflow_h"] + run.periods["outflow_a"]
    # the smoothed outflow keeps the vehicle count up to the smoothing's lag: summing
    # q_k - q_(k-1) = a (o_k - q_(k-1)) gives sum q = sum o - (q_T - q_0) (1/a - 1)
    a = 1.0 - math.exp(-run.sumo.control_period / run.settings.smoothing)
    lag = (data.outflow[-1] - run.q_nominal) * (1.0 / a - 1.0)
    assert data.outflow.sum() == pytest.approx(total.sum() - lag, rel=1e-12)


@pytest.mark.sumo
def test_replaying_the_data_reproduces_the_bridge_replay_twin(run):
    data = replay_data_of(run)
    rr = run_replay(run.scenario.params, data, replay_options_of(run.settings))
    status = run.twin_status["replay"]
    if status["resyncs"]:      # identical up to the period of the first re-sync
        k_end = int(np.searchsorted(run.t, status["first_resync_s"] - 1e-9))
        assert rr.stopped is not None and run.t[k_end - 1] < rr.stopped <= run.t[k_end]
    else:
        k_end = run.t.size
        assert rr.stopped is None and np.isfinite(run.replay).all()
    assert k_end >= 20, "too few periods before the first re-sync to compare"
    scale = data.scale[None, :, None]
    err = np.abs(rr.fields[:k_end] - run.replay[:k_end]) / scale
    assert np.nanmax(err) <= TOLERANCE and np.isfinite(err).all()


def test_measured_state_fills_empty_cells_with_the_equilibrium_speed():
    p = load_scenario(DEFAULT).params
    rho_h, rho_a = np.array([0.05, 0.0, 0.02]), np.array([0.0, 0.0, 0.03])
    v_h, v_a = np.array([10.0, np.nan, 12.0]), np.array([np.nan, np.nan, 8.0])
    z = measured_state(p, rho_h, v_h, rho_a, v_a)
    ve_h, ve_a = equilibrium_speeds(p, rho_h, rho_a)
    np.testing.assert_array_equal(z[1], [10.0, ve_h[1], 12.0])
    np.testing.assert_array_equal(z[3], [ve_a[0], ve_a[1], 8.0])
    np.testing.assert_array_equal(z[0], [0.05, RHO_FLOOR, 0.02])
    np.testing.assert_array_equal(z[2], [RHO_FLOOR, RHO_FLOOR, 0.03])


def test_smoothing_of_a_step_is_the_exponential():
    dt, tau, q0, c = 1.0, 30.0, 0.5, 1.5
    q = outflow_series(q0, np.full(90, c), dt, tau)
    k = np.arange(1, 91)
    np.testing.assert_allclose(q, c + (q0 - c) * np.exp(-k * dt / tau), rtol=1e-12)
    assert smooth_step(2.0, 4.0, 1e9, tau) == 4.0
    p = load_scenario(DEFAULT).params
    start = np.array([0.04, 20.0, 0.02, 15.0])
    cells = np.tile([0.06, 10.0, 0.03, 9.0], (3, 1))
    got = inlet_series(p, start, cells, dt, tau)
    a = 1 - math.exp(-dt / tau)
    np.testing.assert_allclose(got[0], start + a * (cells[0] - start), rtol=1e-15)
    np.testing.assert_allclose(got[2], cells[0] + (1 - a) ** 3 * (start - cells[0]),
                               rtol=1e-12)
