"""The references a held-out replay error is judged against, on cases with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.identify import ReplayData
from arzsumo.identify.three_detector import Triangle
from arzsumo.model.params import ModelParameters
from arzsumo.workflows.identify.references import (
    decomposition,
    reference_scores,
    reference_triangle,
)

X = (np.arange(20) + 0.5) * 50.0
T = np.arange(1, 451, dtype=float)
FD = Triangle(v_free=22.0, w=8.0, rho_jam=0.2)


def _run(rho: float, share: float, scale_rho: float, wave: float = 0.0,
         name: str = "seed4") -> ReplayData:
    """A stationary congested state on FD's branch (rho veh/m, AV share), speeds
    perturbed by ``wave`` m/s travelling upstream at FD.w, scale at ``scale_rho``."""
    q = FD.w * (FD.rho_jam - rho)
    v = q / rho + wave * np.sin(2 * np.pi * (X[None, :] + FD.w * T[:, None]) / 400.0)
    fields = np.stack([np.full_like(v, rho * (1 - share)), v,
                       np.full_like(v, rho * share), v], axis=1)
    state = np.array([rho * (1 - share), q / rho, rho * share, q / rho])
    return ReplayData.from_arrays(
        T, X, fields, np.repeat(state[:, None], X.size, 1), np.tile(state, (T.size, 1)),
        np.full(T.size, q), scale=np.array([scale_rho * (1 - share), q / rho,
                                            scale_rho * share, q / rho]), name=name)


def test_the_exact_solution_scores_zero_and_the_constant_its_offset():
    doc = reference_scores(FD, [_run(0.1, 0.2, 0.125)])
    run = doc["runs"]["seed4"]
    assert run["three_detector"] == pytest.approx({"rho_h": 0.0, "rho_a": 0.0}, abs=1e-9)
    # every block at 0.1 against an equilibrium of 0.125: 20 % of it
    assert run["equilibrium"] == pytest.approx({"rho_h": 0.2, "rho_a": 0.2}, rel=1e-9)
    assert run["place_mean"] == pytest.approx({"rho_h": 0.0, "rho_a": 0.0}, abs=1e-12)
    assert doc["triangle"] == {"v_free": 22.0, "w": 8.0, "rho_jam": 0.2}


def test_the_place_mean_leaves_the_variation_in_time():
    """Blocks alternating +-10 % of the equilibrium in time about it: the equilibrium is
    10 % off; the place's mean (23 high blocks, 22 low) leaves the spread about it."""
    run = _run(0.1, 0.2, 0.1)
    fields = run.fields.copy()
    sign = np.where((np.arange(T.size) // 10) % 2 == 0, 1.1, 0.9)    # per 10 s block
    fields[:, [0, 2]] *= sign[:, None, None]
    run = ReplayData.from_arrays(T, X, fields, run.initial, run.inlet, run.outflow,
                                 scale=run.scale, name="seed4")
    doc = reference_scores(FD, [run])["runs"]["seed4"]
    blocks = sign[::10]
    spread = float(np.sqrt(np.mean((blocks - blocks.mean()) ** 2)))   # 0.0999753...
    assert doc["place_mean"] == pytest.approx({"rho_h": spread, "rho_a": spread}, rel=1e-9)
    assert doc["equilibrium"] == pytest.approx({"rho_h": 0.1, "rho_a": 0.1}, rel=1e-9)


def test_the_triangle_passes_through_the_training_mean_at_the_measured_wave_speed():
    params = ModelParameters()
    fd = reference_triangle(params, [_run(0.1, 0.2, 0.1, wave=1.0, name="seed1")])
    assert fd.v_free == params.v_free_h
    assert fd.w == pytest.approx(FD.w, rel=0.05)           # read from the speed field
    # rho_jam = rho + q / w on the measured wave speed: FD's own within the reading
    q = FD.w * (FD.rho_jam - 0.1)
    assert fd.rho_jam == pytest.approx(0.1 + q / fd.w, rel=1e-6)
    assert fd.rho_jam == pytest.approx(FD.rho_jam, rel=0.05)


def test_a_replay_offset_by_a_constant_is_all_bias_and_in_phase():
    run = _run(0.1, 0.2, 0.1)
    fields = run.fields.copy()
    sign = np.where((np.arange(T.size) // 10) % 2 == 0, 1.1, 0.9)
    fields[:, [0, 2]] *= sign[:, None, None]
    run = ReplayData.from_arrays(T, X, fields, run.initial, run.inlet, run.outflow,
                                 scale=run.scale, name="seed4")
    shifted = fields.copy()
    shifted[:, 0] += 0.005                                 # 6.25 % of rho_h* = 0.08
    parts = decomposition(run, shifted)
    assert parts["rho_h"]["bias"] == pytest.approx(0.0625, rel=1e-9)
    assert parts["rho_h"]["offset"] == pytest.approx(0.0625, rel=1e-9)
    assert parts["rho_h"]["fluctuation"] == pytest.approx(0.0, abs=1e-12)
    assert parts["rho_h"]["correlation"] == pytest.approx(1.0, rel=1e-12)
    assert parts["rho_a"] == pytest.approx({"offset": 0.0, "bias": 0.0, "fluctuation": 0.0,
                                            "correlation": 1.0}, abs=1e-12)
    # a replay that holds each place's mean: no bias, the run's spread, no phase
    flat = np.broadcast_to(fields.mean(axis=0, keepdims=True), fields.shape).copy()
    held = decomposition(run, flat)["rho_h"]
    assert held["bias"] == pytest.approx(0.0, abs=1e-9)
    assert held["fluctuation"] == pytest.approx(0.1, rel=0.01)
    assert np.isnan(held["correlation"])
