"""Linearisation and characteristic (Riemann) form of the 4x4 model (paper, section 2).

The derivation, with every sign and normalisation, is in ``docs/characteristic_form.md``:
z_t + A z_x = B z for the deviations z = (rho_h~, v_h~, rho_a~, v_a~) (section 1); the
eigenvalues in the paper's order lambda_1 = v_h*, lambda_2 = larger eigenvalue of the
density Jacobian J, lambda_3 = v_a*, lambda_4 = smaller one, lambda_4 < 0 in congestion
(section 2); rows of T normalised so that every Riemann variable w = T z is a speed in m/s
(section 3); the scaled variables w-bar and Sigma(x) of clpsys1-clpsys4 (section 4); Q, R,
kappa and U-bar (section 5).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from arzsumo.errors import ModelError
from arzsumo.model.equilibrium import Equilibrium
from arzsumo.model.fd import equilibrium_speeds, speed_jacobian
from arzsumo.model.params import ModelParameters


def _frozen(a: ArrayLike) -> np.ndarray:
    out = np.array(a, dtype=float)
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class CharacteristicSystem:
    """A linear n+1 hyperbolic system in scaled Riemann variables (clpsys1-clpsys4).

    n states w+ travel downstream at ``lam[:n] > 0``, one state w- upstream at
    ``lam[n] < 0``. The in-domain coupling is Sigma(x) built from the constant matrix
    ``j_hat`` (see :meth:`sigma`); boundaries are w+(0) = Q w-(0), w-(L) = R w+(L) + U-bar.

    Parameters
    ----------
    lam : array, shape (n+1,)
        Characteristic speeds, m/s.
    j_hat : array, shape (n+1, n+1)
        Source coupling in unscaled Riemann variables, 1/s.
    Q, R : array, shape (n,)
        Boundary coefficients at x = 0 and x = L (dimensionless).
    length : float
        Domain length L, m.
    """

    lam: np.ndarray
    j_hat: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    length: float

    def __post_init__(self) -> None:
        for name in ("lam", "j_hat", "Q", "R"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        n = self.lam.size - 1
        if n < 1 or self.j_hat.shape != (n + 1, n + 1) or self.Q.shape != (n,) \
                or self.R.shape != (n,):
            raise ModelError(f"inconsistent shapes: lam {self.lam.shape}, j_hat "
                             f"{self.j_hat.shape}, Q {self.Q.shape}, R {self.R.shape}")
        if np.any(self.lam[:n] <= 0) or self.lam[n] >= 0:
            raise ModelError(f"lam = {self.lam.tolist()} is not allowed: n positive speeds "
                             "then one negative (congested traffic)")

    @property
    def n(self) -> int:
        """Number of downstream-travelling states."""
        return self.lam.size - 1

    @property
    def lam_plus(self) -> np.ndarray:
        """Lambda+ = (lambda_1, ..., lambda_n), m/s."""
        return self.lam[: self.n]

    @property
    def lam_minus(self) -> float:
        """Lambda- = -lambda_{n+1} > 0, m/s."""
        return float(-self.lam[self.n])

    @property
    def t_f(self) -> float:
        """Finite convergence time L / min(Lambda+) + L / Lambda-, s (first theorem)."""
        return self.length / float(self.lam_plus.min()) + self.length / self.lam_minus

    def scaling(self, x: ArrayLike) -> np.ndarray:
        """Factors exp(-J_hat_ii x / lambda_i), shape (len(x), n+1): w-bar = factor * w."""
        x = np.atleast_1d(np.asarray(x, float))
        return np.exp(-np.outer(x, np.diag(self.j_hat) / self.lam))

    def sigma(self, x: ArrayLike) -> np.ndarray:
        """Sigma(x), shape (len(x), n+1, n+1), zero diagonal, 1/s.

        Blocks: Sigma++ = [:n, :n], Sigma+- = [:n, n], Sigma-+ = [n, :n].
        """
        x = np.atleast_1d(np.asarray(x, float))
        rate = np.diag(self.j_hat) / self.lam                     # J_hat_ii / lambda_i
        expo = np.exp(x[:, None, None] * (rate[None, None, :] - rate[None, :, None]))
        out = self.j_hat[None, :, :] * expo
        idx = np.arange(self.n + 1)
        out[:, idx, idx] = 0.0
        return out


@dataclass(frozen=True)
class Linearization:
    """The model linearised at an equilibrium, with its characteristic form.

    Attributes
    ----------
    equilibrium : Equilibrium
    A, B : arrays (4, 4)
        Quasi-linear and source matrices of z_t + A z_x = B z.
    eigenvalues : array (4,)
        lambda_1..lambda_4 in the paper's order (module docstring), m/s.
    T : array (4, 4)
        w = T z, rows normalised as in docs/characteristic_form.md, section 3.
    """

    equilibrium: Equilibrium
    A: np.ndarray
    B: np.ndarray
    eigenvalues: np.ndarray
    T: np.ndarray

    @cached_property
    def T_inv(self) -> np.ndarray:
        """nu = T^-1; its columns are right eigenvectors of A."""
        return np.linalg.inv(self.T)

    @cached_property
    def j_hat(self) -> np.ndarray:
        """J_hat = T B T^-1, the source in unscaled Riemann variables, 1/s."""
        return self.T @ self.B @ self.T_inv

    @cached_property
    def kappa(self) -> np.ndarray:
        """kappa_j = v_h nu_1j + rho_h nu_2j + v_a nu_3j + rho_a nu_4j (flow per unit w_j)."""
        eq = self.equilibrium          # (v_h, rho_h, v_a, rho_a) . z: linearised flow deviation
        return np.array([eq.v_h, eq.rho_h, eq.v_a, eq.rho_a]) @ self.T_inv

    @property
    def regime(self) -> str:
        """'congested' when lambda_4 < 0, else 'free'."""
        return "congested" if self.eigenvalues[3] < 0 else "free"

    @property
    def t_f(self) -> float:
        """L / min(lambda_1, lambda_3) + L / (-lambda_4), s; inf in free flow."""
        lam = self.eigenvalues
        if lam[3] >= 0:
            return float("inf")
        length = self.equilibrium.params.length
        return length / min(lam[0], lam[2]) + length / (-lam[3])

    @cached_property
    def Q(self) -> np.ndarray:
        """w+(0) = Q w-(0) from rho_h~(0) = rho_a~(0) = 0 and zero inflow deviation."""
        c = np.vstack([self.T_inv[0], self.T_inv[2], self.kappa])
        return -np.linalg.solve(c[:, :3], c[:, 3])

    @cached_property
    def u_bar_per_u(self) -> float:
        """U-bar / U = exp(-J_hat_44 L / lambda_4) / kappa_4, in (m/s) per (veh/s)."""
        length = self.equilibrium.params.length
        return float(np.exp(-self.j_hat[3, 3] * length / self.eigenvalues[3]) / self.kappa[3])

    @cached_property
    def R(self) -> np.ndarray:
        """w-bar_4(L) = R w-bar+(L) + U-bar, in scaled variables."""
        lam, jh, k = self.eigenvalues, self.j_hat, self.kappa
        length = self.equilibrium.params.length
        rate = np.diag(jh) / lam
        return -(k[:3] / k[3]) * np.exp((rate[:3] - rate[3]) * length)

    @cached_property
    def system(self) -> CharacteristicSystem:
        """The generic n+1 form (n = 3) used by the kernel solver; needs congestion."""
        if self.regime != "congested":
            raise ModelError(
                f"lambda_4 = {self.eigenvalues[3]:.4g} m/s is not allowed for boundary control: "
                "the equilibrium must be congested (lambda_4 < 0)")
        return CharacteristicSystem(self.eigenvalues, self.j_hat, self.Q, self.R,
                                    self.equilibrium.params.length)

    def to_riemann(self, z: ArrayLike, x: ArrayLike) -> np.ndarray:
        """Scaled Riemann variables w-bar(x) from deviations z, shape (4, len(x))."""
        w = self.T @ np.asarray(z, float)
        return w * self._scaling(x).T

    def from_riemann(self, w_bar: ArrayLike, x: ArrayLike) -> np.ndarray:
        """Deviations z from scaled Riemann variables, inverse of :meth:`to_riemann`."""
        w = np.asarray(w_bar, float) / self._scaling(x).T
        return self.T_inv @ w

    def u_bar(self, u: ArrayLike) -> np.ndarray | float:
        """U-bar from the physical flow deviation U (veh/s)."""
        return np.asarray(u, float) * self.u_bar_per_u

    def _scaling(self, x: ArrayLike) -> np.ndarray:
        x = np.atleast_1d(np.asarray(x, float))
        return np.exp(-np.outer(x, np.diag(self.j_hat) / self.eigenvalues))


def quasi_linear_matrix(eq: Equilibrium) -> np.ndarray:
    """A of z_t + A z_x = B z at the equilibrium, m/s and mixed units (docs/characteristic_form.md,
    section 1)."""
    s = speed_jacobian(eq.params, eq.rho_h, eq.rho_a)
    rh, ra, vh, va = eq.rho_h, eq.rho_a, eq.v_h, eq.v_a
    return np.array([
        [vh, rh, 0.0, 0.0],
        [0.0, vh + rh * s[0, 0], s[0, 1] * (va - vh), ra * s[0, 1]],
        [0.0, 0.0, va, ra],
        [s[1, 0] * (vh - va), rh * s[1, 0], 0.0, va + ra * s[1, 1]],
    ])


def source_matrix(eq: Equilibrium) -> np.ndarray:
    """B of z_t + A z_x = B z: the linearised relaxation (Ve_i - v_i) / tau_i, 1/s."""
    p = eq.params
    s = speed_jacobian(p, eq.rho_h, eq.rho_a)
    b = np.zeros((4, 4))
    b[1] = [s[0, 0] / p.tau_h, -1.0 / p.tau_h, s[0, 1] / p.tau_h, 0.0]
    b[3] = [s[1, 0] / p.tau_a, 0.0, s[1, 1] / p.tau_a, -1.0 / p.tau_a]
    return b


def characteristic_speeds(p: ModelParameters, rho_h: ArrayLike, rho_a: ArrayLike) -> np.ndarray:
    """lambda_1..lambda_4 (m/s) at equilibria (rho_h, rho_a), shape (..., 4), vectorised."""
    rho_h = np.asarray(rho_h, float)
    rho_a = np.asarray(rho_a, float)
    v_h, v_a = equilibrium_speeds(p, rho_h, rho_a)
    s = speed_jacobian(p, rho_h, rho_a)
    j11 = v_h + rho_h * s[..., 0, 0]
    j22 = v_a + rho_a * s[..., 1, 1]
    j12j21 = rho_h * s[..., 0, 1] * rho_a * s[..., 1, 0]   # >= 0: J has real eigenvalues
    mean = 0.5 * (j11 + j22)
    disc = np.sqrt(0.25 * (j11 - j22) ** 2 + j12j21)
    return np.stack([v_h, mean + disc, v_a, mean - disc], axis=-1)


def _riemann_matrix(eq: Equilibrium, lam: np.ndarray) -> np.ndarray:
    """T with rows the normalised left eigenvectors of A (docs/characteristic_form.md, 3)."""
    s = speed_jacobian(eq.params, eq.rho_h, eq.rho_a)
    area = np.array([eq.params.area_h, eq.params.area_a])
    rho = np.array([eq.rho_h, eq.rho_a])
    speed = np.array([eq.v_h, eq.v_a])
    if abs(eq.v_h - eq.v_a) < 1e-9 * max(eq.v_h, eq.v_a):
        raise ModelError(f"v_h = v_a = {eq.v_h:.6g} m/s is not allowed: the characteristic "
                         "form needs distinct class speeds (strict hyperbolicity)")
    t = np.zeros((4, 4))
    t[0] = [-s[0, 0], 1.0, -s[0, 1], 0.0]           # HV Lagrangian marker, speed v_h
    t[2] = [-s[1, 0], 0.0, -s[1, 1], 1.0]           # AV Lagrangian marker, speed v_a
    for row in (1, 3):                              # density waves, eigenvalues of J
        p_vec = area / (lam[row] - speed)           # left eigenvector of J
        q_vec = p_vec * rho / (lam[row] - speed)    # > 0 componentwise
        p_vec, q_vec = p_vec / q_vec.sum(), q_vec / q_vec.sum()
        t[row] = [p_vec[0] - q_vec @ s[:, 0], q_vec[0], p_vec[1] - q_vec @ s[:, 1], q_vec[1]]
    return t


def linearize(eq: Equilibrium) -> Linearization:
    """Linearise the 4x4 model at ``eq`` and build its characteristic form."""
    lam = characteristic_speeds(eq.params, eq.rho_h, eq.rho_a)
    return Linearization(eq, quasi_linear_matrix(eq), source_matrix(eq), lam,
                         _riemann_matrix(eq, lam))
