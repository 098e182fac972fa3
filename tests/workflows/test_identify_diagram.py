"""Stage 1's glue on synthetic runs with a known answer: densities that travel upstream
at a known speed c, with speeds on a known Newell diagram. The wave reader must read c,
and the fit must recover the diagram from the windows' block states."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.identify.data import ReplayData
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.scenario import scenario_from_dict
from arzsumo.workflows.identify.diagram import fit_stage_one, read_waves, stationary_states

MODEL = {"family": "newell", "ao_max_h": 0.62, "ao_max_a": 0.6, "wave_speed_h_kmh": 33,
         "wave_speed_a_kmh": 38, "corner": 6, "v_free_h_kmh": 80, "v_free_a_kmh": 60}
RHO = (0.100, 0.022)
C = -35 / 3.6          # the waves' speed, m/s


def _run(params, seed: int) -> ReplayData:
    """600 s x 1 km (1 s, 50 m): rho_i = rho_i* (1 + 0.12 g(t - (x - L) / C)) with g a
    smoothed random signal (not periodic), speeds Ve_i at those densities."""
    rng = np.random.default_rng(seed)
    t = np.arange(1.0, 601.0)
    x = 25.0 + 50.0 * np.arange(20)
    s = np.arange(-200.0, 700.0)
    g = np.convolve(rng.standard_normal(s.size), np.ones(25) / 25, mode="same")
    g /= np.abs(g).max()
    phase = t[:, None] - (x[None, :] - 1000.0) / C
    pulse = np.interp(phase, s, g)
    rho_h, rho_a = RHO[0] * (1 + 0.12 * pulse), RHO[1] * (1 + 0.12 * pulse)
    v_h, v_a = equilibrium_speeds(params, rho_h, rho_a)
    fields = np.stack([rho_h, v_h, rho_a, v_a], axis=1)
    return ReplayData(t, x, fields, fields[0], fields[:, :, 0], rho_h[:, -1] * v_h[:, -1]
                      + rho_a[:, -1] * v_a[:, -1], name=f"r{seed}")


@pytest.fixture(scope="module")
def runs():
    sc = scenario_from_dict({"model": MODEL, "equilibrium": {"rho_h_veh_km": 100,
                                                             "rho_a_veh_km": 22}}, "x.toml")
    return sc, [_run(sc.params, seed) for seed in (1, 2, 3)]


def test_the_wave_reader_reads_the_speed_the_waves_travel_at(runs):
    _, data = runs
    reading = read_waves(data)
    for cls in ("h", "a"):
        assert len(reading.per_run[cls]) == 3
        assert reading.mean(cls) == pytest.approx(C, rel=0.05)
    assert reading.stream == pytest.approx(C, rel=0.05)


def test_stage_one_recovers_the_diagram_it_was_made_with(runs):
    sc, data = runs
    start = sc.with_({"model.ao_max_h": 0.9, "model.ao_max_a": 0.9,
                      "model.wave_speed_h_kmh": 15, "model.wave_speed_a_kmh": 15})
    fit, reading, states = fit_stage_one(start, "newell", data, RHO)
    assert states.size == len(data) * 10 * 20     # 100 m x 30 s blocks of 1 km x 600 s
    np.testing.assert_array_equal(np.unique(states.run), [0, 1, 2])
    assert stationary_states(data).size == states.size
    np.testing.assert_allclose([fit.params.ao_max_h, fit.params.ao_max_a], [0.62, 0.6],
                               rtol=0.03)
    assert fit.rmse["h"] < 0.1 and fit.rmse["a"] < 0.1       # m/s: on the curve
    assert fit.lambda_4 == pytest.approx(reading.stream, rel=0.05)
    assert fit.params.tau_h == sc.params.tau_h                # stage 2's business


def test_a_jam_floor_above_the_blocks_lets_the_branch_through_them_despite_denser_cells(runs):
    """Stopped vehicles make single cells far denser than any block: a floor above every
    cell keeps the jam occupancy there and misses the diagram; the blocks' floor does not."""
    from arzsumo.model.fd import area_occupancy

    sc, data = runs
    dense = []
    for d in data:
        fields = np.array(d.fields)
        fields[::97, ::2, ::7] *= 2.2        # a stopped platoon in one cell now and then
        dense.append(ReplayData(d.t, d.x, fields, d.initial, d.inlet, d.outflow, name=d.name))
    cells = float(np.max(area_occupancy(sc.params, np.concatenate(
        [d.fields[:, 0].ravel() for d in dense]), np.concatenate(
        [d.fields[:, 2].ravel() for d in dense]))))
    assert cells > 0.62 * 1.1
    on_blocks, _, _ = fit_stage_one(sc, "newell", dense, RHO)
    on_cells, _, _ = fit_stage_one(sc, "newell", dense, RHO, floor=cells)
    assert on_blocks.params.ao_max_h == pytest.approx(0.62, rel=0.05)
    assert on_cells.params.ao_max_h >= cells
    assert on_cells.rmse["h"] > 2 * on_blocks.rmse["h"]
