"""Design conditions select1-select4 and the minimum dwell time tau* of minimalthm.

Interpretations where the paper is ambiguous (stated so the numbers can be checked):

* q_i are the entries of Q (clpsys3); j_i is the norm of column i of Sigma++(L) (the
  "element in coefficient matrix Sigma++" multiplying alpha_i(L) in G(L, t)).
* epsilon_i = 8 l_i(L, L)^2 lambda_i^2 + 8 j_i ||R||^2 (Lemma bounddt, as printed).
* p_1 = 1 / ||inverse transform||^2 and p_3 = the smallest weight of V (norm equivalences),
  gamma as printed in the proof of Theorem minimalthm with A = max A_i.
* phi_1 (bounddt) = (8 N(L,L)^2 Lambda-^2 + 2 (R Sigma+-(L))^2) ||R||^2,
  phi_2 (bounddt) = 8/p_3 (c_1 + c_2/p_1) + 8 c_3 ||R||^2 / p_3 with c_1..c_3 as printed.
* c_4 bounds 2 ||R Lambda+||^2 ||alpha_x(L, t)||^2 and depends on the trajectory; we take
  it from a given state's alpha_x(L) (the sinusoidal initial condition by default).
* varphi_1 = 1/(2 zeta) - mu sigma, varphi_2 = 1 + phi_1 + (1 - sigma) mu / (2 zeta)
  - gamma + eta, varphi_3 = B e^{mu L/Lambda-} (phi_2 + c_4)/(mu sigma) + 1 + eta + phi_1,
  and tau* = int_0^1 ds / (varphi_1 s^2 + varphi_2 s + varphi_3) (Psi runs from 0 to 1;
  the paper's upper limit L is a typo).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from arzsumo.control.etc import EtcDesign
from arzsumo.control.kernels import Kernels, trapezoid_weights
from arzsumo.control.transform import BacksteppingTransform
from arzsumo.model.characteristic import CharacteristicSystem


@dataclass(frozen=True)
class Condition:
    """One design condition: its label, whether it holds, and the two sides compared."""

    label: str
    statement: str
    lhs: float
    rhs: float
    holds: bool

    def __post_init__(self) -> None:
        object.__setattr__(self, "lhs", float(self.lhs))
        object.__setattr__(self, "rhs", float(self.rhs))
        object.__setattr__(self, "holds", bool(self.holds))


@dataclass(frozen=True)
class DesignReport:
    """The conditions checked, tau* (s) and the constants they use."""

    conditions: tuple[Condition, ...]
    tau_star: float
    constants: dict[str, float]

    @property
    def all_hold(self) -> bool:
        """Whether every condition holds (the design meets the theorems' hypotheses)."""
        return all(c.holds for c in self.conditions)

    def failing(self) -> list[str]:
        """Names of the failing conditions; a repeated label gets its number (select1 #2)."""
        labels = [c.label for c in self.conditions]
        names, seen = [], dict.fromkeys(labels, 0)
        for c in self.conditions:
            seen[c.label] += 1
            if not c.holds:
                names.append(c.label if labels.count(c.label) == 1 else
                             f"{c.label} #{seen[c.label]}")
        return names

    def verdict(self) -> str:
        """One line: all conditions hold, or how many fail and which."""
        bad, n = self.failing(), len(self.conditions)
        if not bad:
            return f"all {n} conditions hold"
        return f"{len(bad)} of {n} conditions fail: {', '.join(bad)}"


def _inverse_norm(kernels: Kernels) -> float:
    """Spectral norm of the discrete inverse transform in the trapezoid L2 inner product."""
    n, nodes = kernels.K.shape[0], kernels.n_cells + 1
    tr = BacksteppingTransform(kernels)
    eye = np.eye((n + 1) * nodes).reshape(-1, n + 1, nodes)
    cols = [tr.inverse(e[:n], e[n]).ravel() for e in eye]
    return float(np.linalg.norm(np.array(cols).T, 2))


@dataclass(frozen=True)
class _Constants:
    """The constants of bounddt and minimalthm (module docstring); eps has one entry per
    positive-speed state."""

    eps: np.ndarray
    p1: float
    p3: float
    gamma: float
    c1: float
    c2: float
    c3: float
    c4: float
    phi1: float
    phi2: float
    b_exp: float


def inverse_p1(kernels: Kernels) -> float:
    """p_1 = 1 / ||inverse transform||^2 (on at most about 60 cells; dimensionless)."""
    coarse = kernels if kernels.n_cells <= 60 else _coarsen(kernels)
    return 1.0 / _inverse_norm(coarse) ** 2


def boundary_eps(system: CharacteristicSystem, kernels: Kernels) -> np.ndarray:
    """epsilon_i of Lemma bounddt, one per positive-speed state (1/s^2)."""
    n, lam, r_norm = system.n, system.lam_plus, float(np.linalg.norm(system.R))
    j = np.linalg.norm(system.sigma(kernels.x)[-1, :n, :n], axis=0)
    return 8 * kernels.L[:, -1, -1]**2 * lam**2 + 8 * j * r_norm**2


def coupling_bound(system: CharacteristicSystem, kernels: Kernels, p1: float) -> float:
    """max ||Sigma++|| + (1 + 1/p_1) max ||Sigma+-|| over [0, L], 1/s (the factor of gamma)."""
    n, sig = system.n, system.sigma(kernels.x)
    sig_pp_max = float(np.linalg.norm(sig[:, :n, :n], axis=(1, 2)).max())
    sig_pm_max = float(np.linalg.norm(sig[:, :n, n], axis=1).max())
    return sig_pp_max + (1 + 1 / p1) * sig_pm_max


def _inverse_kernel_bounds(system: CharacteristicSystem, kernels: Kernels,
                           sig: np.ndarray) -> tuple[float, float, float]:
    """c_1, c_2, c_3 of bounddt from the inverse kernels' last row L(L, xi), N(L, xi)."""
    n, lam, lm = system.n, system.lam_plus, system.lam_minus
    w = trapezoid_weights(kernels.n_cells, kernels.h)[-1]
    l_row, n_row = kernels.L[:, -1, :], kernels.N[-1, :]
    l_xi = np.gradient(l_row, kernels.x, axis=1)
    n_xi = np.gradient(n_row, kernels.x)
    c1 = max(float(w @ np.sum((l_xi * lam[:, None]) ** 2, axis=0)), float(w @ (n_xi * lm) ** 2))
    c2 = max(float(w @ np.linalg.norm(np.einsum("il,lij->lj", l_row, sig[:, :n, :n]),
                                       axis=1) ** 2),
             float(w @ (np.einsum("il,li->l", l_row, sig[:, :n, n])) ** 2))
    s_pm_l = sig[-1, :n, n]
    c3 = max(float(w @ (np.linalg.norm(s_pm_l) * np.linalg.norm(l_row, axis=0)) ** 2),
             float(w @ (np.linalg.norm(s_pm_l) * n_row) ** 2))
    return c1, c2, c3


def _constants(system: CharacteristicSystem, kernels: Kernels, design: EtcDesign,
               alpha_x_at_l: np.ndarray | None) -> _Constants:
    """Every constant the conditions and tau* use (module docstring)."""
    n, lam, lm = system.n, system.lam_plus, system.lam_minus
    A, r = np.array(design.A), system.R
    sig = system.sigma(kernels.x)
    r_norm = float(np.linalg.norm(r))
    b_exp = design.B * math.exp(design.mu * system.length / lm)
    eps = boundary_eps(system, kernels)
    p1 = inverse_p1(kernels)
    # p_3: the smallest weight of V
    p3 = float(min((A / lam * np.exp(-design.mu * system.length / lam)).min(), design.B / lm))
    c1, c2, c3 = _inverse_kernel_bounds(system, kernels, sig)
    s_pm_l = sig[-1, :n, n]
    phi1 = (8 * kernels.N[-1, -1] ** 2 * lm**2 + 2 * float(r @ s_pm_l) ** 2) * r_norm**2
    phi2 = 8 / p3 * (c1 + c2 / p1) + 8 * c3 * r_norm**2 / p3
    gamma = 2 * A.max() / (p3 * lam.min()) * coupling_bound(system, kernels, p1)
    ax = np.zeros(n) if alpha_x_at_l is None else np.asarray(alpha_x_at_l)
    c4 = 2 * float(np.linalg.norm(r * lam)) ** 2 * float(ax @ ax)
    return _Constants(eps, p1, p3, gamma, c1, c2, c3, c4, phi1, phi2, b_exp)


def _select_conditions(system: CharacteristicSystem, design: EtcDesign,
                       k: _Constants) -> list[Condition]:
    """select1 and select3 for each varsigma_i, select2 and select4 for varsigma_{n+1}."""
    n, lam, length, mu_d = system.n, system.lam_plus, system.length, design.mu
    A, vs, zeta, eps = np.array(design.A), np.array(design.varsigma), design.zeta, k.eps
    aq = float(A @ system.Q**2)
    conds = []
    for i in range(n):
        need = max(zeta * k.b_exp * eps[i], zeta * mu_d * eps[i])
        conds.append(Condition("select1", f"varsigma_{i + 1} >= max(zeta B e^(mu L/Lambda-) "
                               f"eps_{i + 1}, zeta mu eps_{i + 1})", vs[i], need, vs[i] >= need))
    need4 = max(0.0, -2 * zeta * mu_d * (aq - design.B))
    conds.append(Condition("select2", "varsigma_4 >= max(0, -2 zeta mu (sum A_i q_i^2 - B))",
                           vs[n], need4, vs[n] >= need4))
    for i in range(n):
        bound = A[i] * math.exp(-mu_d * length / lam[i])
        conds.append(Condition("select3", f"varsigma_{i + 1} <= A_{i + 1} e^(-mu L/lambda_"
                               f"{i + 1})", vs[i], bound, vs[i] <= bound))
    conds.append(Condition("select4", "varsigma_4 + sum A_i q_i^2 - B <= 0",
                           vs[n] + aq - design.B, 0.0, vs[n] + aq - design.B <= 0))
    return conds


def _decay_conditions(design: EtcDesign, gamma: float) -> list[Condition]:
    """esthm: V_d decays (mu (1 - sigma) > gamma) and eta is at least that rate."""
    rate = design.mu * (1 - design.sigma) - gamma
    return [Condition("esthm", "mu (1 - sigma) - gamma > 0 (decay rate of V_d)",
                      rate, 0.0, rate > 0),
            Condition("esthm", "eta >= mu (1 - sigma) - gamma", design.eta, rate,
                      design.eta >= rate)]


def _tau_star(design: EtcDesign, k: _Constants) -> tuple[float, tuple[float, float, float]]:
    """tau* (s) of minimalthm and its varphi_1..3."""
    zeta, sigma, eta, mu_d = design.zeta, design.sigma, design.eta, design.mu
    vphi1 = 1 / (2 * zeta) - mu_d * sigma
    vphi2 = 1 + k.phi1 + (1 - sigma) * mu_d / (2 * zeta) - k.gamma + eta
    vphi3 = k.b_exp * (k.phi2 + k.c4) / (mu_d * sigma) + 1 + eta + k.phi1
    tau, _ = quad(lambda s: 1.0 / (vphi1 * s * s + vphi2 * s + vphi3), 0.0, 1.0)
    return float(tau), (vphi1, vphi2, vphi3)


def check_design(system: CharacteristicSystem, kernels: Kernels, design: EtcDesign,
                 alpha_x_at_l: np.ndarray | None = None) -> DesignReport:
    """Evaluate select1-select4, the decay condition of esthm, and tau* (module docstring)."""
    k = _constants(system, kernels, design, alpha_x_at_l)
    conds = _select_conditions(system, design, k) + _decay_conditions(design, k.gamma)
    tau, (vphi1, vphi2, vphi3) = _tau_star(design, k)
    constants = {"p1": float(k.p1), "p3": k.p3, "gamma": k.gamma, "c1": k.c1, "c2": k.c2,
                 "c3": k.c3, "c4": k.c4, "phi1": k.phi1, "phi2": k.phi2, "varphi1": vphi1,
                 "varphi2": vphi2, "varphi3": vphi3, "B_exp": k.b_exp}
    constants.update({f"eps_{i + 1}": float(k.eps[i]) for i in range(system.n)})
    return DesignReport(tuple(conds), tau, {name: float(v) for name, v in constants.items()})


def _coarsen(kernels: Kernels, target: int = 50) -> Kernels:
    """Kernels sampled on about ``target`` cells (for the dense norm computation)."""
    step = max(1, kernels.n_cells // target)
    sub = np.s_[..., ::step, ::step]
    return Kernels(kernels.x[::step], kernels.K[sub], kernels.M[sub], kernels.L[sub],
                   kernels.N[sub])
