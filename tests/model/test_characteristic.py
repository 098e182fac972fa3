"""Invariants of the linearisation and the characteristic form (paper, section 2)."""

import numpy as np
import pytest

from arzsumo.model import (
    ModelParameters,
    characteristic_speeds,
)
from arzsumo.model.fd import equilibrium_speeds, speed_jacobian


def test_eigendecomposition_reconstructs_A(preset_lin):
    lin = preset_lin
    recon = lin.T_inv @ np.diag(lin.eigenvalues) @ lin.T
    np.testing.assert_allclose(recon, lin.A, atol=1e-12 * np.abs(lin.A).max())
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(lin.A).real),
                               np.sort(lin.eigenvalues), rtol=1e-9)


def test_class_speeds_are_exact_characteristic_speeds(preset_lin):
    eq, lam = preset_lin.equilibrium, preset_lin.eigenvalues
    assert lam[0] == eq.v_h
    assert lam[2] == eq.v_a


def test_ordering_condition_and_congestion(preset_lin):
    l1, l2, l3, l4 = preset_lin.eigenvalues
    assert l4 < min(l1, l3) < l2 < max(l1, l3)
    assert min(l1, l2, l3) > 0 > l4
    assert preset_lin.regime == "congested"


def test_rows_of_T_are_normalised_speeds(preset_lin):
    # documented normalisation: coefficients on v_h~ and v_a~ sum to one
    np.testing.assert_allclose(preset_lin.T[:, 1] + preset_lin.T[:, 3], 1.0, rtol=1e-12)


@pytest.mark.parametrize("rho_h", [0.05, 0.12, 0.30])
def test_single_class_limit_gives_classic_arz_speeds(rho_h):
    """As rho_a -> 0 the HV pair tends to v* and v* + rho* Ve'(rho*); the AV density wave
    collapses onto v_a, so {lambda_2, lambda_4} -> {v* + rho* Ve', v_a}."""
    p = ModelParameters()
    lam = characteristic_speeds(p, rho_h, 1e-8)
    ve_h, ve_a = equilibrium_speeds(p, rho_h, 0.0)
    dve = speed_jacobian(p, rho_h, 0.0)[0, 0]
    assert lam[0] == pytest.approx(ve_h, rel=1e-6)                      # v*
    np.testing.assert_allclose(sorted([lam[1], lam[3]]),
                               sorted([ve_h + rho_h * dve, ve_a]), rtol=1e-5)
    if rho_h == 0.30:       # congested: the upstream wave is the classic ARZ one
        assert lam[3] == pytest.approx(ve_h + rho_h * dve, rel=1e-6)


def test_T_is_invertible_and_well_conditioned(preset_lin):
    assert np.linalg.cond(preset_lin.T) < 1e4
    np.testing.assert_allclose(preset_lin.T @ preset_lin.T_inv, np.eye(4), atol=1e-12)


def _inlet_residual(lin, z):
    eq = lin.equilibrium
    g = np.array([eq.v_h, eq.rho_h, eq.v_a, eq.rho_a])
    return np.array([z[0], z[2], g @ z])


def test_inlet_conditions_in_z_and_w_accept_the_same_states(preset_lin):
    lin = preset_lin
    rng = np.random.default_rng(1)
    # states satisfying the z conditions: the null space of the three linear constraints
    eq = lin.equilibrium
    c = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [eq.v_h, eq.rho_h, eq.v_a, eq.rho_a]])
    null = np.linalg.svd(c)[2][-1]
    for _ in range(20):
        z_ok = rng.normal() * null
        w = lin.to_riemann(z_ok[:, None], [0.0])[:, 0]
        np.testing.assert_allclose(w[:3], lin.Q * w[3], atol=1e-12 * np.abs(w).max())
        z_bad = z_ok + rng.normal(size=4) * 1e-2
        w_bad = lin.to_riemann(z_bad[:, None], [0.0])[:, 0]
        assert np.abs(w_bad[:3] - lin.Q * w_bad[3]).max() > 1e-6
    # and every w with w+ = Q w- maps to a z that satisfies them
    for w4 in rng.normal(size=10):
        w = np.append(lin.Q * w4, w4)
        z = lin.from_riemann(w[:, None], [0.0])[:, 0]
        np.testing.assert_allclose(_inlet_residual(lin, z), 0.0, atol=1e-12)


def test_outlet_condition_in_w_gives_the_commanded_flow(preset_lin):
    lin = preset_lin
    eq = lin.equilibrium
    g = np.array([eq.v_h, eq.rho_h, eq.v_a, eq.rho_a])
    length = eq.params.length
    rng = np.random.default_rng(2)
    for _ in range(20):
        w_plus, u = rng.normal(size=3), rng.normal() * 0.1
        w = np.append(w_plus, lin.R @ w_plus + lin.u_bar(u))
        z = lin.from_riemann(w[:, None], [length])[:, 0]
        assert g @ z == pytest.approx(u, abs=1e-12)
    assert lin.u_bar(0.3) / lin.u_bar_per_u == pytest.approx(0.3)


def test_source_vanishes_on_the_equilibrium_manifold(preset_lin):
    lin = preset_lin
    eq = lin.equilibrium
    s = speed_jacobian(eq.params, eq.rho_h, eq.rho_a)
    for dr in np.eye(2):                        # tangent of {v_i = Ve_i(rho)}
        z = np.array([dr[0], s[0] @ dr, dr[1], s[1] @ dr])
        np.testing.assert_allclose(lin.B @ z, 0.0, atol=1e-15)
    # and the nonlinear relaxation term (Ve_i - v_i) / tau_i is zero at the equilibrium
    ve = equilibrium_speeds(eq.params, eq.rho_h, eq.rho_a)
    assert (ve[0] - eq.v_h, ve[1] - eq.v_a) == (0.0, 0.0)


def test_scaled_riemann_system_matches_the_linear_pde(base_lin):
    """For any smooth z(x, t): residual of clpsys1-2 in w-bar = E(x) T (residual in z)."""
    lin = base_lin
    sysm = lin.system
    x = np.linspace(0, 1000, 7)
    k, om = 2 * np.pi / 800, 0.05
    amp = np.array([0.01, 0.5, 0.008, 0.3])
    t = 3.0
    z = amp[:, None] * np.sin(k * x - om * t)
    z_x = amp[:, None] * k * np.cos(k * x - om * t)
    z_t = -amp[:, None] * om * np.cos(k * x - om * t)
    res_z = z_t + lin.A @ z_x - lin.B @ z
    e = sysm.scaling(x).T                                     # (4, N)
    rate = (np.diag(lin.j_hat) / lin.eigenvalues)[:, None]
    w_bar = lin.to_riemann(z, x)
    w_bar_t = e * (lin.T @ z_t)
    w_bar_x = e * (lin.T @ z_x) - rate * w_bar
    sig = sysm.sigma(x)
    res_w = w_bar_t + lin.eigenvalues[:, None] * w_bar_x - np.einsum("nij,jn->in", sig, w_bar)
    np.testing.assert_allclose(res_w, e * (lin.T @ res_z), atol=1e-12)
    assert np.all(np.diagonal(sig, axis1=1, axis2=2) == 0)


def test_t_f_formula(base_lin):
    lam, length = base_lin.eigenvalues, 1000.0
    assert base_lin.t_f == pytest.approx(length / min(lam[0], lam[2]) + length / -lam[3])
    assert base_lin.system.t_f == pytest.approx(base_lin.t_f)
