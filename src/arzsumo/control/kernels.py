r"""Backstepping kernels K, M (label back4) and inverse kernels L, N (label invback).

Kernel equations
----------------
For the n+1 system clpsys1-clpsys4 in scaled Riemann variables (n states w+ at speeds
lambda_i > 0, one state w- at speed -mu, mu = Lambda- > 0, Sigma-- = 0), the transform

    alpha = w+,   beta(x) = w-(x) - int_0^x K(x, xi) w+(xi) + M(x, xi) w-(xi) dxi

maps the plant onto the target system tarsys1-tarsys4 (beta_t - mu beta_x = 0) if and only
if K = (k_1..k_n) and M satisfy, on T = {0 <= xi <= x <= L},

    mu dK/dx - dK/dxi Lambda+ = K Sigma++(xi) + M Sigma-+(xi)      (n transport equations)
    dM/dx + dM/dxi           = K Sigma+-(xi) / mu                  (1 transport equation)
    k_i(x, x)   = -Sigma-+_i(x) / (lambda_i + mu)                  (on the diagonal)
    M(x, 0)     = sum_i k_i(x, 0) lambda_i Q_i / mu                 (on xi = 0)

(Derivation: differentiate beta, integrate the w+_xi and w-_xi terms by parts and collect
the coefficients of w+(x), w-(0) and of w+(xi), w-(xi) under the integral; the w-(x) terms
cancel identically.) This is the n+1 structure of Di Meglio, Vazquez and Krstic (2013) and
Hu, Di Meglio, Vazquez and Krstic (2015) with one negative speed. With our normalisation
of T (docs/characteristic_form.md) the signs are exactly as written; for the mixed ARZ
model Sigma+- = 0, so M is constant along the diagonal direction.

The k_i characteristics run in direction (mu, -lambda_i) from the diagonal; the M
characteristics run along (1, 1) from xi = 0. The solution of the target system for
t >= L/mu + L/min(lambda_i) is zero: the paper's finite time t_f.

Numerical method
----------------
A marching method of characteristics on the uniform grid x_j = j h, xi_l = l h
(h = L / n_cells), row by row in x; every row is vectorised over xi:

* k_i(x_j, xi_l): the characteristic is traced back until it meets the previous row
  x = x_{j-1} (at xi_l + lambda_i h / mu) or the diagonal, whichever comes first; values at
  the foot are cubic Lagrange interpolants of the previous row (or the exact diagonal
  condition); the ODE along the characteristic is integrated with Heun's method
  (trapezoid rule with an explicit predictor).
* M(x_j, xi_l): its characteristic meets the grid node (x_{j-1}, xi_{l-1}) exactly;
  trapezoid rule again, and the boundary condition on xi = 0.

Local errors are O(h^3) (trapezoid) and O(h^4) (cubic interpolation), so the method is
**second-order accurate** (checked in tests and ``benchmarks/bench_kernels.py``).

The inverse kernels L, N (label invback) are obtained by inverting the discretised
Volterra operator (trapezoid rule), which is second-order accurate as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_triangular

from arzsumo.errors import ModelError, require
from arzsumo.model.characteristic import CharacteristicSystem


@dataclass(frozen=True)
class Kernels:
    """Kernels on the grid x_j = j h, j = 0..n_cells; entry [.., j, l] is at (x_j, xi_l).

    Entries with l > j (outside the triangle) are zero. Kernels in 1/m.
    """

    x: np.ndarray       # the grid (n_cells+1,), m
    K: np.ndarray       # k_1..k_n, (n, n_cells+1, n_cells+1)
    M: np.ndarray       # (n_cells+1, n_cells+1)
    L: np.ndarray       # inverse kernels of invback, like K
    N: np.ndarray       # and like M

    @property
    def n_cells(self) -> int:
        return self.x.size - 1

    @property
    def h(self) -> float:
        return float(self.x[1] - self.x[0])


@dataclass(frozen=True)
class _KernelProblem:
    """The kernel equations' data on the grid, and their pointwise pieces (vectorised).

    ``sig_nodes`` is Sigma at the nodes, shape (n_cells+1, n+1, n+1); ``s_pm_nodes`` its
    Sigma+- block, shape (n_cells+1, n); speeds in m/s, Q dimensionless.
    """

    system: CharacteristicSystem
    x: np.ndarray
    sig_nodes: np.ndarray
    s_pm_nodes: np.ndarray

    @classmethod
    def on_grid(cls, system: CharacteristicSystem, n_cells: int) -> _KernelProblem:
        x = np.linspace(0.0, system.length, n_cells + 1)
        sig_nodes = system.sigma(x)
        return cls(system, x, sig_nodes, sig_nodes[:, :system.n, system.n])

    @property
    def h(self) -> float:
        return self.x[1] - self.x[0]

    def k_diag(self, xd: np.ndarray) -> np.ndarray:
        """k_i on the diagonal at positions xd (boundary condition): shape (n, len(xd))."""
        n, lam, mu = self.system.n, self.system.lam_plus, self.system.lam_minus
        return (-self.system.sigma(xd)[:, n, :n] / (lam + mu)).T

    def m_bc(self, k0: np.ndarray) -> float:
        """M(x, 0) from k_i(x, 0) (boundary condition on xi = 0)."""
        return float((k0 * self.system.lam_plus) @ self.system.Q / self.system.lam_minus)

    def rhs_k(self, kv: np.ndarray, mv: np.ndarray, sig: np.ndarray) -> np.ndarray:
        """(K Sigma++ + M Sigma-+)_i at points: kv (n, P), mv (P,), sig (P, n+1, n+1)."""
        n = self.system.n
        return np.einsum("mp,pmi->ip", kv, sig[:, :n, :n]) + mv * sig[:, n, :n].T

    def g_m(self, kv: np.ndarray, s_pm: np.ndarray) -> np.ndarray:
        """K Sigma+- / mu at points: kv (n, P), s_pm (P, n)."""
        return np.einsum("mp,pm->p", kv, s_pm) / self.system.lam_minus


def solve_kernels(system: CharacteristicSystem, n_cells: int) -> Kernels:
    """Solve the kernel equations (module docstring) on ``n_cells`` uniform cells.

    ``system`` is any n+1 system (n >= 1); the grid has n_cells + 1 nodes; cost
    O(n_cells^2).
    """
    require(isinstance(n_cells, int | np.integer) and n_cells >= 4, "n_cells", n_cells,
            "an integer >= 4", ModelError)
    prob = _KernelProblem.on_grid(system, n_cells)
    K = np.zeros((system.n, n_cells + 1, n_cells + 1))
    M = np.zeros((n_cells + 1, n_cells + 1))
    K[:, 0, 0] = prob.k_diag(prob.x[:1])[:, 0]
    M[0, 0] = prob.m_bc(K[:, 0, 0])
    for j in range(1, n_cells + 1):
        _march_diagonal(prob, K, M, j)
        K[:, j, :j], M[j, :j] = _march_row(prob, K, M, j)
    L, N = _invert_volterra(K, M, prob.h)
    return Kernels(prob.x, K, M, L, N)


def _march_diagonal(prob: _KernelProblem, K: np.ndarray, M: np.ndarray, j: int) -> None:
    """Fill the diagonal node (x_j, x_j): k exact, M by the trapezoid rule along (1, 1)
    from (x_{j-1}, x_{j-1})."""
    x, h, s_pm = prob.x, prob.h, prob.s_pm_nodes
    K[:, j, j] = prob.k_diag(x[j:j + 1])[:, 0]
    M[j, j] = M[j - 1, j - 1] + 0.5 * h * (
        prob.g_m(K[:, j, j:j + 1], s_pm[j:j + 1])[0]
        + prob.g_m(K[:, j - 1, j - 1:j], s_pm[j - 1:j])[0])


def _k_feet(prob: _KernelProblem, K: np.ndarray, M: np.ndarray,
            j: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Feet of the k_i characteristics through (x_j, xi_l), l < j: on the previous row
    x_{j-1}, or on the diagonal, whichever comes first.

    Returns the step along each characteristic s (n, j), s; k_i at its own foot (n, j),
    1/m; and the right-hand side K Sigma++ + M Sigma-+ at the feet (n, j), 1/m^2.
    """
    system, x, h = prob.system, prob.x, prob.h
    n, lam, mu = system.n, system.lam_plus, system.lam_minus
    xi = x[:j]
    xi_row = xi[None, :] + (lam[:, None] / mu) * h             # (n, j)
    on_row = xi_row <= x[j - 1] + 1e-12 * h
    s_diag = (x[j] - xi[None, :]) / (lam[:, None] + mu)
    s = np.where(on_row, h / mu, s_diag)                       # characteristic step
    xf = np.where(on_row, x[j - 1], x[j] - mu * s_diag)
    xif = np.where(on_row, xi_row, xf)                         # diagonal: xi = x
    row_vals = np.concatenate([K[:, j - 1, :j], M[None, j - 1, :j]])
    foot_row = interpolate(x[:j], row_vals, xif)                 # (n+1, n, j)
    m_on_diag = interpolate(x[: j + 1], np.diag(M)[None, : j + 1], xf)[0]
    k_on_diag = prob.k_diag(xf.ravel()).reshape(n, n, j)
    foot_k = np.where(on_row[None], foot_row[:n], k_on_diag)   # [m, i, l]: k_m at foot i
    foot_m = np.where(on_row, foot_row[n], m_on_diag)          # [i, l]
    sig_f = system.sigma(xif.ravel()).reshape(n, j, n + 1, n + 1)
    rhs_f = np.einsum("mil,ilmi->il", foot_k, sig_f[:, :, :n, :n]) \
        + foot_m * np.einsum("ili->il", sig_f[:, :, n, :n])
    own_k = np.einsum("iil->il", foot_k)                       # k_i at its own foot
    return s, own_k, rhs_f


def _march_row(prob: _KernelProblem, K: np.ndarray, M: np.ndarray,
               j: int) -> tuple[np.ndarray, np.ndarray]:
    """k_i(x_j, xi_l) (n, j) and M(x_j, xi_l) (j,), l < j, 1/m: Heun's method along the
    characteristics (predictor, then corrector), M(x_j, 0) from its boundary condition."""
    s, own_k, rhs_f = _k_feet(prob, K, M, j)
    h, s_pm = prob.h, prob.s_pm_nodes
    m_prev = np.concatenate([[0.0], M[j - 1, : j - 1]])        # M(x_{j-1}, xi_{l-1})
    g_prev = np.concatenate([[0.0], prob.g_m(K[:, j - 1, : j - 1], s_pm[: j - 1])])
    k_node = own_k + s * rhs_f
    m_node = m_prev + h * g_prev
    m_node[0] = prob.m_bc(k_node[:, 0])
    k_node = own_k + 0.5 * s * (rhs_f + prob.rhs_k(k_node, m_node, prob.sig_nodes[:j]))
    m_node = m_prev + 0.5 * h * (g_prev + prob.g_m(k_node, s_pm[:j]))
    m_node[0] = prob.m_bc(k_node[:, 0])
    return k_node, m_node


def trapezoid_weights(n_cells: int, h: float) -> np.ndarray:
    """W[j, l] = h c_l^(j): trapezoid weights of int_0^{x_j} on the grid (lower triangle)."""
    w = np.tril(np.full((n_cells + 1, n_cells + 1), h))
    idx = np.arange(n_cells + 1)
    w[:, 0] *= 0.5
    w[idx, idx] *= 0.5
    w[0, 0] = 0.0
    return w


def _invert_volterra(K: np.ndarray, M: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """L, N of invback by inverting the discretised forward transform.

    beta = (I - W o M) w- - sum_i (W o K_i) w+_i, hence
    w- = beta + (I - W o M)^-1 - I) beta + (I - W o M)^-1 (W o K_i) alpha_i, and the
    kernels are the matrices divided by the trapezoid weights.
    """
    n_nodes = M.shape[0]
    w = trapezoid_weights(n_nodes - 1, h)
    a = np.eye(n_nodes) - w * M
    eye = np.eye(n_nodes)
    inv = solve_triangular(a, eye, lower=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        n_mat = np.where(w > 0, (inv - eye) / w, 0.0)
        l_mat = np.stack([np.where(w > 0, solve_triangular(a, w * k, lower=True) / w, 0.0)
                          for k in K])
    return l_mat, n_mat


# piecewise Lagrange interpolation on a uniform grid (the kernel solver, the linear plant)
def lagrange_stencil(nodes: np.ndarray, x_eval: np.ndarray,
                     order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Indices and weights for interpolating at ``x_eval`` from ``order`` nearby nodes.

    ``nodes`` is uniform; the stencil is centred on the interval holding each point and
    shifted near the ends (fewer nodes than ``order`` lower the order). Returns
    ``idx, w`` of shape (*x_eval.shape, p) with f(x_eval) = sum(w * f[idx], axis=-1).
    """
    m = nodes.size
    p = min(order, m)
    if p == 1:
        shape = (*x_eval.shape, 1)
        return np.zeros(shape, int), np.ones(shape)
    h = nodes[1] - nodes[0]
    base = np.floor((x_eval - nodes[0]) / h + 1e-9).astype(int)
    start = np.clip(base - (p // 2 - 1), 0, m - p)
    idx = start[..., None] + np.arange(p)
    xs = nodes[idx]
    w = np.ones_like(xs)
    for a in range(p):
        for b in range(p):
            if a != b:
                w[..., a] *= (x_eval - xs[..., b]) / (xs[..., a] - xs[..., b])
    return idx, w


def interpolate(nodes: np.ndarray, values: np.ndarray, x_eval: np.ndarray,
                order: int = 4) -> np.ndarray:
    """Values (C, m) on ``nodes`` interpolated at ``x_eval`` (any shape E): (C, *E)."""
    idx, w = lagrange_stencil(nodes, x_eval, order)
    return np.sum(w * values[:, idx], axis=-1)
