"""Kernel equations (back4), their numerical order, the 2x2 case and the inverse kernels."""

import numpy as np
import pytest

from arzsumo.control.kernels import solve_kernels
from arzsumo.model.characteristic import CharacteristicSystem


def single_class_arz(v_free, rho_max, gamma, tau, rho, length, inlet):
    """Known-answer reference: the linearised single-class ARZ model (n = 1) in the
    characteristic form of the mixed model.

    rho_t + (rho v)_x = 0, (v - Ve)_t + v (v - Ve)_x = (Ve - v) / tau with
    Ve(rho) = V (1 - (rho / rho_max)^gamma) (Yu and Krstic, 2019). At (rho*, v* = Ve(rho*))
    the speeds are lambda_1 = v* (w_1 = v~ - Ve'(rho*) rho~) and lambda_2 = v* + rho* Ve'
    (w_2 = v~), rows normalised like the mixed model (speed coefficient one); the outlet
    is v* rho~ + rho* v~ = U. ``inlet``: "flow" (constant inflow, as in the mixed model)
    or "reflecting-free" (Q = 0, which has a closed-form kernel). Units m, s, veh/m.
    """
    v = v_free * (1 - (rho / rho_max) ** gamma)
    dve = -v_free * gamma / rho_max * (rho / rho_max) ** (gamma - 1)
    return _single_class_system(v, dve, tau, rho, length, inlet)


def single_class_newell(v_free, rho_jam, w, n, tau, rho, length, inlet):
    """The same reference on the smoothed Newell speed, written out here independently of
    arzsumo.model.fd: Ve = (V^-n + C^-n)^(-1/n), C = w (rho_jam / rho - 1)."""
    c = w * (rho_jam / rho - 1)
    dc = -w * rho_jam / rho ** 2
    v = (v_free ** -n + c ** -n) ** (-1 / n)
    dve = (v_free ** -n + c ** -n) ** (-1 / n - 1) * c ** (-n - 1) * dc
    return _single_class_system(v, dve, tau, rho, length, inlet)


def _single_class_system(v, dve, tau, rho, length, inlet):
    lam = np.array([v, v + rho * dve])
    assert lam[1] < 0, "the equilibrium must be congested"
    t = np.array([[-dve, 1.0], [0.0, 1.0]])
    t_inv = np.linalg.inv(t)
    b = np.array([[0.0, 0.0], [dve / tau, -1.0 / tau]])
    j_hat = t @ b @ t_inv
    kappa = np.array([v, rho]) @ t_inv
    # "flow": one downstream-travelling state, hence one inlet condition kappa . w(0) = 0
    q = {"flow": np.array([-kappa[1] / kappa[0]]), "reflecting-free": np.zeros(1)}[inlet]
    rate = np.diag(j_hat) / lam
    r = np.array([-(kappa[0] / kappa[1]) * np.exp((rate[0] - rate[1]) * length)])
    return CharacteristicSystem(lam, j_hat, q, r, length)


@pytest.fixture(scope="module", params=["power", "newell"])
def base_system(request):
    """The paper's base case on each fundamental-diagram family."""
    from arzsumo.model import PRESETS, equilibrium_from_densities, linearize
    from tests.conftest import NEWELL_CHANGES

    p = PRESETS["paper_base"]
    params = p.params if request.param == "power" else p.params.with_(**NEWELL_CHANGES)
    return linearize(equilibrium_from_densities(params, p.rho_h, p.rho_a)).system


def test_boundary_conditions_hold_exactly(base_system):
    s = base_system
    k = solve_kernels(s, 100)
    sig = s.sigma(k.x)
    n = s.n
    diag = np.einsum("ijj->ij", k.K)
    np.testing.assert_allclose(diag, (-sig[:, n, :n] / (s.lam_plus + s.lam_minus)).T)
    np.testing.assert_allclose(k.M[:, 0], (k.K[:, :, 0].T * s.lam_plus) @ s.Q / s.lam_minus,
                               rtol=1e-12, atol=1e-20)


def test_kernel_pdes_are_satisfied(base_system):
    """Finite-difference residual of mu K_x - K_xi Lambda+ - K Sigma++ - M Sigma-+ = 0."""
    s = base_system
    n_cells = 200
    k = solve_kernels(s, n_cells)
    h, mu, n = k.h, s.lam_minus, s.n
    sig = s.sigma(k.x)
    j, l = np.meshgrid(np.arange(2, n_cells - 1), np.arange(2, n_cells - 1), indexing="ij")
    inside = l < j - 2
    j, l = j[inside], l[inside]
    kx = (k.K[:, j + 1, l] - k.K[:, j - 1, l]) / (2 * h)
    kxi = (k.K[:, j, l + 1] - k.K[:, j, l - 1]) / (2 * h)
    source = np.einsum("mp,pmi->ip", k.K[:, j, l], sig[l][:, :n, :n]) \
        + k.M[j, l] * sig[l][:, n, :n].T
    residual = mu * kx - s.lam_plus[:, None] * kxi - source
    scale = np.abs(mu * kx).max() + np.abs(source).max()
    assert np.abs(residual).max() < 1e-3 * scale
    mx = (k.M[j + 1, l] - k.M[j - 1, l]) / (2 * h)
    mxi = (k.M[j, l + 1] - k.M[j, l - 1]) / (2 * h)
    m_source = np.einsum("ip,pi->p", k.K[:, j, l], sig[l][:, :n, n]) / mu
    assert np.abs(mx + mxi - m_source).max() < 1e-3 * (np.abs(mx).max() + 1e-30)


def test_grid_convergence_is_second_order(base_system):
    values = []
    for n_cells in (50, 100, 200, 400):
        k = solve_kernels(base_system, n_cells)
        values.append(np.array([k.K[0, -1, 0], k.K[2, -1, 0], k.M[-1, 0]]))
    values = np.array(values)
    diffs = np.abs(np.diff(values, axis=0))            # successive differences
    orders = np.log2(diffs[:-1] / diffs[1:])
    assert np.all(orders > 1.6), orders        # second order (k_3 converges even faster)


SINGLE_CLASS = {
    "power": lambda inlet: single_class_arz(80 / 3.6, 0.2, 2.0, 30.0, 0.13, 1000.0, inlet),
    "newell": lambda inlet: single_class_newell(80 / 3.6, 0.2, 35 / 3.6, 4.0, 30.0, 0.13,
                                                1000.0, inlet),
}


def test_the_newell_reference_is_the_models_single_class_limit():
    """The independently written Newell reference has the model's lambda_2 = Q_e'."""
    from arzsumo.model import PRESETS, characteristic_speeds

    p = PRESETS["paper_base"].params.with_(
        family="newell", ao_max_h=0.2 * 16 / 6.5, ao_max_a=0.9, wave_speed_h=35 / 3.6,
        wave_speed_a=35 / 3.6, corner=4.0)
    ref = SINGLE_CLASS["newell"]("flow")
    lam = characteristic_speeds(p, 0.13, 1e-10)
    assert -ref.lam_minus == pytest.approx(lam[3], rel=1e-6)
    assert ref.lam_plus[0] == pytest.approx(lam[0], rel=1e-6)


@pytest.mark.parametrize("family", sorted(SINGLE_CLASS))
def test_single_class_closed_form_without_inlet_reflection(family):
    """Q = 0: M = 0 and k is constant along (mu, -lambda) from the diagonal, so
    k(x, xi) = -Sigma-+((lambda x + mu xi) / (lambda + mu)) / (lambda + mu)."""
    s = SINGLE_CLASS[family]("reflecting-free")
    k = solve_kernels(s, 100)
    lam, mu = s.lam_plus[0], s.lam_minus
    xx, xi = np.meshgrid(k.x, k.x, indexing="ij")
    foot = (lam * xx + mu * xi) / (lam + mu)
    exact = -s.sigma(foot.ravel())[:, 1, 0].reshape(xx.shape) / (lam + mu)
    lower = xi <= xx
    if family == "power":
        np.testing.assert_allclose(k.K[0][lower], exact[lower], rtol=1e-7, atol=1e-15)
    else:   # Sigma varies faster along the slow wave: second order, no longer exact
        fine = solve_kernels(s, 200)
        errors = [np.abs(kk.K[0] - ex)[lo].max() / np.abs(ex).max() for kk, ex, lo in (
            (k, exact, lower), (fine, _closed_form(s, fine.x), np.tril(np.ones((201,) * 2,
                                                                           bool))))]
        assert errors[0] < 3e-4 and errors[0] / errors[1] > 3.5, errors
    assert np.abs(k.M).max() == 0.0


def _closed_form(s, x):
    lam, mu = s.lam_plus[0], s.lam_minus
    xx, xi = np.meshgrid(x, x, indexing="ij")
    foot = (lam * xx + mu * xi) / (lam + mu)
    return -s.sigma(foot.ravel())[:, 1, 0].reshape(xx.shape) / (lam + mu)


def _first_order_reference(s, n_cells):
    """Independent donor-cell discretisation of the n = 1 kernel equations."""
    lam, mu, q = s.lam_plus[0], s.lam_minus, s.Q[0]
    x = np.linspace(0, s.length, n_cells + 1)
    h = x[1] - x[0]
    sig_mp = s.sigma(x)[:, 1, 0]
    k = np.zeros((n_cells + 1, n_cells + 1))
    m = np.zeros_like(k)
    k[0, 0] = -sig_mp[0] / (lam + mu)
    m[0, 0] = lam * q * k[0, 0] / mu
    for j in range(1, n_cells + 1):
        k[j, j] = -sig_mp[j] / (lam + mu)
        m[j, 1:j + 1] = m[j - 1, :j]                  # M_x + M_xi = 0 (Sigma+- = 0)
        for ll in range(j - 1, -1, -1):
            rhs = mu * k[j - 1, ll] + lam * k[j, ll + 1]
            if ll == 0:   # M(x_j, 0) = lam q k(x_j, 0) / mu, solved together with k
                k[j, 0] = rhs / (mu + lam - h * sig_mp[0] * lam * q / mu)
                m[j, 0] = lam * q * k[j, 0] / mu
            else:
                k[j, ll] = (rhs + h * m[j, ll] * sig_mp[ll]) / (mu + lam)
    return x, k, m


@pytest.mark.parametrize("family", sorted(SINGLE_CLASS))
def test_single_class_agrees_with_an_independent_discretisation(family):
    s = SINGLE_CLASS[family]("flow")
    ours = solve_kernels(s, 50)
    lower = np.tril(np.ones((51, 51), bool))
    scale = np.abs(ours.K[0]).max()
    errors = []
    for n_ref in (400, 800):
        _, k_ref, m_ref = _first_order_reference(s, n_ref)
        sub = np.s_[::n_ref // 50, ::n_ref // 50]
        errors.append(np.abs(ours.K[0][lower] - k_ref[sub][lower]).max() / scale)
        if n_ref == 800 and family == "power":  # first-order reference at h = 1.25 m
            assert errors[-1] < 5e-3
            assert np.abs(ours.M[lower] - m_ref[sub][lower]).max() < 5e-3 * np.abs(m_ref).max()
    # the first-order reference closes in on ours at its own order (Newell: 1.7 % -> 0.8 %)
    assert errors[1] < 1e-2 and 1.8 < errors[0] / errors[1] < 2.7, errors


def test_inverse_kernels_solve_the_resolvent_equations(base_system, request):
    """L(x, xi) = K(x, xi) + int_xi^x N(x, s) K(s, xi) ds and the same for N with M.

    To 1e-3 on the power law; on the Newell family the residual is 5e-3 at 200 cells and
    halves with the cell size (0.55, 0.27, 0.14 % at 200, 400, 800 cells)."""
    rel = {"power": 1e-3, "newell": 1e-2}[request.node.callspec.params["base_system"]]
    k = solve_kernels(base_system, 200)
    j = 200
    for l_idx in (0, 50, 150):
        s_idx = np.arange(l_idx, j + 1)
        integral_n = np.trapezoid(k.N[j, s_idx] * k.M[s_idx, l_idx], k.x[s_idx])
        assert k.N[j, l_idx] == pytest.approx(k.M[j, l_idx] + integral_n, rel=rel, abs=1e-12)
        for i in range(3):
            integral_l = np.trapezoid(k.N[j, s_idx] * k.K[i, s_idx, l_idx], k.x[s_idx])
            assert k.L[i, j, l_idx] == pytest.approx(k.K[i, j, l_idx] + integral_l,
                                                     rel=rel, abs=1e-12)


def test_too_few_cells_is_refused(base_system):
    from arzsumo.errors import ModelError

    with pytest.raises(ModelError, match="n_cells = 2 "):
        solve_kernels(base_system, 2)
