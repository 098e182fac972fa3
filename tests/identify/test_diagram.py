"""Stage 1: Edie block states and the diagram fit against synthetic data with a known
answer (a Newell model's speeds plus noise, and its own lambda_4 as the wave target)."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.errors import ArzsumoError
from arzsumo.identify.data import ReplayData
from arzsumo.identify.diagram import StationaryStates, block_states, fit_diagram
from arzsumo.model import PRESETS, characteristic_speeds
from arzsumo.model.fd import area_occupancy, speed_of_ao

TRUE = PRESETS["paper_base"].params.with_(
    family="newell", ao_max_h=0.62, ao_max_a=0.6, wave_speed_h=33 / 3.6,
    wave_speed_a=38 / 3.6, corner=6.0, v_free_h=80 / 3.6, v_free_a=60 / 3.6)


def _states(p, n=400, noise=0.3, seed=1, runs=4):
    """Blocks around (100, 22) veh/km with the class mix varying, speeds from ``p``."""
    rng = np.random.default_rng(seed)
    scale = rng.uniform(0.75, 1.2, n)
    rho_h = 0.100 * scale * rng.uniform(0.95, 1.05, n)
    rho_a = 0.022 * scale * rng.uniform(0.9, 1.1, n)
    v_h, v_a = speed_of_ao(p, area_occupancy(p, rho_h, rho_a))
    return StationaryStates(rho_h, rho_a, v_h + noise * rng.standard_normal(n),
                            v_a + noise * rng.standard_normal(n), np.arange(n) % runs)


def test_the_fit_recovers_a_known_newell_diagram_and_its_wave_speed():
    states = _states(TRUE)
    lam4 = float(characteristic_speeds(TRUE, 0.1, 0.022)[3])
    guess = TRUE.with_(ao_max_h=0.75, ao_max_a=0.75, wave_speed_h=20 / 3.6,
                       wave_speed_a=20 / 3.6)
    fit = fit_diagram(guess, states, lam4, (0.1, 0.022), bootstrap=5)
    assert fit.which == ("wave_speed_h", "wave_speed_a", "ao_max_h", "ao_max_a")
    np.testing.assert_allclose(fit.values, [33 / 3.6, 38 / 3.6, 0.62, 0.6], rtol=0.03)
    assert fit.lambda_4 == pytest.approx(lam4, rel=0.01)
    assert fit.rmse["h"] == pytest.approx(0.3, rel=0.15)   # the noise, not model error
    assert (fit.sigma > 0).all() and (fit.sigma < 0.05 * fit.values).all()
    assert fit.bootstrap_sigma is not None and fit.bootstrap_sigma.shape == (4,)
    # the parameters not in stage 1 stay as they were given
    assert fit.params.tau_h == guess.tau_h and fit.params.v_free_h == guess.v_free_h


def test_the_wave_target_moves_the_fit_where_the_scatter_alone_cannot_decide():
    """Blocks in a narrow AO band trade w against AO_jam; the wave residual decides."""
    states = _states(TRUE, noise=0.3)
    lam4 = float(characteristic_speeds(TRUE, 0.1, 0.022)[3])
    guess = TRUE.with_(wave_speed_h=20 / 3.6, wave_speed_a=20 / 3.6)
    fast = fit_diagram(guess, states, 1.4 * lam4, (0.1, 0.022), wave_weight=1.0)
    assert fast.lambda_4 < 1.15 * lam4 < 0          # pulled towards the faster target
    assert fast.rmse["h"] > 0.3                       # at a price in the speed fit


def test_the_power_family_fits_its_own_names():
    p = PRESETS["paper_base"].params.with_(ao_max_h=0.62, ao_max_a=0.6, gamma_h=1.2,
                                           gamma_a=1.0)
    states = _states(p, noise=0.2)
    lam4 = float(characteristic_speeds(p, 0.1, 0.022)[3])
    fit = fit_diagram(p.with_(gamma_h=2.0, gamma_a=2.0), states, lam4, (0.1, 0.022))
    assert fit.which == ("ao_max_h", "ao_max_a", "gamma_h", "gamma_a")
    np.testing.assert_allclose(fit.values, [0.62, 0.6, 1.2, 1.0], rtol=0.05)


def test_too_few_blocks_are_refused():
    with pytest.raises(ArzsumoError, match=r"stationary blocks = 3 .*at least 10"):
        fit_diagram(TRUE, _states(TRUE, n=3), -9.0, (0.1, 0.022))


def _data(fields):
    t = np.arange(1, fields.shape[0] + 1, dtype=float)
    x = 25.0 + 50.0 * np.arange(fields.shape[2])
    init = np.nan_to_num(fields[0], nan=1.0)
    inlet = np.tile(init[:, 0], (fields.shape[0], 1))
    return ReplayData(t, x, fields, init, inlet, np.full(fields.shape[0], 1.0))


def test_block_states_are_edie_means_and_skip_incomplete_blocks():
    fields = np.empty((60, 4, 4))
    fields[:, 0], fields[:, 2] = 0.1, 0.02
    fields[:, 1], fields[:, 3] = 8.0, 7.0
    fields[:30, 0, :2] = 0.2                       # a denser first half, same speed
    fields[:30, 1, :2] = 2.0                       # ... and slower: flow 0.4 vs 0.3
    fields[40, 0, 3], fields[40, 1, 3] = 0.0, np.nan   # an empty cell: no speed, no flow
    fields[41, 0, 0] = np.nan                       # an unobserved density
    s = block_states(_data(fields), cells=2, periods=30)
    assert s.size == 3                              # 2 x 2 blocks, one without density
    # the block with the empty cell: flow 8 * 0.1 in 59 of its 60 cell-periods
    assert s.v_h[2] == pytest.approx(8.0) and s.rho_h[2] == pytest.approx(0.1 * 59 / 60)
    # first block: rho = 0.2, speed = flow / rho = 0.4 / 0.2 = 2
    assert s.rho_h[0] == pytest.approx(0.2) and s.v_h[0] == pytest.approx(2.0)
    # a block half dense-slow, half light-fast would be (0.4 + 0.8) / (0.2 + 0.1) = 4
    mixed = fields.copy()
    mixed[:30, :, :] = fields[:30]
    mixed[:15, 0, :2], mixed[:15, 1, :2] = 0.1, 8.0
    s2 = block_states(_data(mixed), cells=2, periods=30)
    assert s2.v_h[0] == pytest.approx((15 * 0.4 + 15 * 0.8) / (15 * 0.2 + 15 * 0.1))
    assert block_states(_data(fields), cells=2, periods=30, start=100.0).size == 0
