"""Linear string stability: Bando's optimal-velocity criterion (a textbook answer), the
closed-form peak of |G| against a scan, and IDM's derivatives against finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from arzsumo_studies.measures.string_stability import (
    IdmParameters,
    Partials,
    growth_over,
    idm_partials,
    max_string_gain,
    string_gain,
)

from arzsumo.errors import ModelError


@pytest.mark.parametrize(("kappa", "v_prime"), [(1.0, 0.45), (1.0, 0.5), (1.0, 0.6),
                                                 (0.5, 0.2), (0.5, 0.4), (2.0, 1.5)])
def test_optimal_velocity_model_is_stable_iff_v_prime_at_most_half_kappa(kappa, v_prime):
    """Bando et al. (1995): f = kappa (V(s) - v) is string stable iff V'(s) <= kappa / 2;
    unstable, the peak is at omega^2 = kappa V' - kappa^2 / 2."""
    p = Partials(f_s=kappa * v_prime, f_v=-kappa, f_dv=0.0)
    assert p.stable == (v_prime <= kappa / 2)
    gain, omega = max_string_gain(p)
    if p.stable:
        assert (gain, omega) == (1.0, 0.0)
    else:
        assert gain > 1.0
        assert omega ** 2 == pytest.approx(kappa * v_prime - kappa ** 2 / 2, rel=1e-12)


@pytest.mark.parametrize("p", [Partials(0.435, -0.474, 0.534), Partials(0.152, -0.174, 0.547),
                               Partials(0.30, -0.2, 0.1), Partials(0.05, -0.9, 0.3)])
def test_the_closed_form_peak_is_the_scans_maximum(p):
    omega = np.linspace(1e-5, 4.0, 400_001)
    scan = string_gain(p, omega)
    gain, where = max_string_gain(p)
    assert gain == pytest.approx(max(1.0, scan.max()), rel=1e-9)
    assert string_gain(p, np.array([1e-9]))[0] == pytest.approx(1.0, abs=1e-9)
    if not p.stable:
        assert where == pytest.approx(omega[scan.argmax()], abs=1e-4)
    assert growth_over(p, 50) == pytest.approx(gain ** 50, rel=1e-12)


def _idm_acceleration(p: IdmParameters, s: float, v: float, dv: float) -> float:
    star = p.s0 + v * p.T - v * dv / (2 * math.sqrt(p.a * p.b))
    return p.a * (1 - (v / p.v0) ** p.delta - (star / s) ** 2)


@pytest.mark.parametrize(("s", "v"), [(11.0, 29 / 3.6), (25.0, 15.0), (6.0, 3.0)])
def test_idm_partials_are_the_derivatives_of_its_acceleration(s, v):
    p = IdmParameters(a=1.0, b=1.5, T=1.0, s0=2.0, v0=30.0)
    d = idm_partials(p, s, v)
    h = 1e-6
    fd = [(_idm_acceleration(p, s + h, v, 0) - _idm_acceleration(p, s - h, v, 0)) / (2 * h),
          (_idm_acceleration(p, s, v + h, 0) - _idm_acceleration(p, s, v - h, 0)) / (2 * h),
          (_idm_acceleration(p, s, v, h) - _idm_acceleration(p, s, v, -h)) / (2 * h)]
    np.testing.assert_allclose([d.f_s, d.f_v, d.f_dv], fd, rtol=1e-6)
    # at its equilibrium gap an IDM vehicle neither speeds up nor slows down
    assert _idm_acceleration(p, p.equilibrium_gap(v), v, 0.0) == pytest.approx(0, abs=1e-12)


def test_idm_with_flows_calibration_is_string_unstable_in_congestion():
    """Flow's merge calibration (a 1, b 1.5, T 1, s0 2) at 29 km/h and its equilibrium
    gap: unstable, as the convective instability of Flow's merge benchmark needs."""
    p = IdmParameters(a=1.0, b=1.5, T=1.0, s0=2.0, v0=81.6 / 3.6)
    d = idm_partials(p, p.equilibrium_gap(29 / 3.6), 29 / 3.6)
    assert not d.stable and 1.0 < max_string_gain(d)[0] < 1.1


@pytest.mark.parametrize(("args", "match"), [((-0.1, -0.5, 0.1), r"f_s = -0.1"),
                                             ((0.1, 0.5, 0.1), r"f_v = 0.5"),
                                             ((0.1, -0.5, -0.1), r"f_dv = -0.1")])
def test_derivatives_with_the_wrong_sign_are_refused(args, match):
    with pytest.raises(ModelError, match=match):
        Partials(*args)
