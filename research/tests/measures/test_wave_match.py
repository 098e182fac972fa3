"""The wave-matched model: lambda_4 on target, the equilibrium kept (label AOrelation)."""

import numpy as np
import pytest
from arzsumo_studies.measures.wave_match import scaled_exponents, wave_matched

from arzsumo.errors import ModelError
from arzsumo.model import ModelParameters, characteristic_speeds, get_preset
from arzsumo.model.fd import equilibrium_speeds
from arzsumo.units import kmh_to_ms

#: the shipped default's identified model (SI) and its equilibrium densities (veh/m)
DEFAULT = ModelParameters(tau_h=32.0192, tau_a=129.2219, gamma_h=1.056016,
                          gamma_a=0.7304219, ao_max_h=0.672886, ao_max_a=0.6893889,
                          v_free_h=float(kmh_to_ms(65.63659)),
                          v_free_a=float(kmh_to_ms(44.44455)))
RHO = (0.1010331, 0.0224266)


@pytest.mark.parametrize("target_kmh", [-35.0, -10.0, -60.0, 0.0, 5.0])
def test_lambda_4_reaches_the_target_and_the_class_speeds_stay(target_kmh):
    q = wave_matched(DEFAULT, *RHO, float(kmh_to_ms(target_kmh)))
    before, after = characteristic_speeds(DEFAULT, *RHO), characteristic_speeds(q, *RHO)
    assert after[3] == pytest.approx(float(kmh_to_ms(target_kmh)), abs=1e-9)
    np.testing.assert_allclose(equilibrium_speeds(q, *RHO), equilibrium_speeds(DEFAULT, *RHO),
                               rtol=1e-12)
    assert (after[0], after[2]) == pytest.approx((before[0], before[2]), rel=1e-12)
    # a faster upstream wave needs a steeper curve: larger exponents, AO_max nearer AO*
    steeper = target_kmh < -2.55
    assert (q.gamma_h > DEFAULT.gamma_h) == steeper
    assert (q.ao_max_h < DEFAULT.ao_max_h) == steeper


def test_scale_one_is_the_model_itself():
    q = scaled_exponents(DEFAULT, *RHO, 1.0)
    assert (q.ao_max_h, q.ao_max_a) == pytest.approx((DEFAULT.ao_max_h, DEFAULT.ao_max_a),
                                                     rel=1e-12)


def test_single_class_limit_is_linear_in_the_scale():
    # HVs alone: the density Jacobian is triangular, diagonal (v_h + rho_h S_hh, v_a), with
    # rho_h S_hh = -k gamma_h (V_h - v_h), so lambda_2 + lambda_4 - v_a is linear in k
    p = get_preset("paper_base").params
    rho_h = 0.12
    v = float(equilibrium_speeds(p, rho_h, 0.0)[0])
    for k in (1.0, 2.0, 3.0):
        lam = characteristic_speeds(scaled_exponents(p, rho_h, 0.0, k), rho_h, 0.0)
        assert lam[1] + lam[3] - lam[2] == pytest.approx(
            v - k * p.gamma_h * (p.v_free_h - v), rel=1e-10)


def test_a_target_out_of_reach_is_refused():
    with pytest.raises(ModelError, match="out of this model family's reach"):
        wave_matched(DEFAULT, *RHO, float(kmh_to_ms(30.0)))   # faster than the HVs
