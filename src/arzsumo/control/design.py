"""Choosing the ETC design for a linearisation: :func:`design_for` (paper, section 4).

The paper selects its parameters "by select1-select4" (remark after Theorem esthm) and
leaves the choice open. Here the choice is made in a fixed order, each step by one
argument, so that every condition that can hold does hold with a margin of two, and the
one that cannot is named with its reason. The constants are those of
:mod:`arzsumo.control.design_check`, which then verifies the result independently.

1. **A_i and the shape of V** (lyapunov). gamma of Theorem esthm is
   2 A_max / (p_3 min lambda_i) S, with S = max ||Sigma++|| + (1 + 1/p_1) max ||Sigma+-||
   and p_3 the smallest weight of V. For a given mu, A_max / p_3 is smallest, equal to
   max_i lambda_i e^(mu L/lambda_i), when every alpha-weight of V is the same at x = L:
   A_i = c lambda_i e^(mu L/lambda_i). So gamma(mu) = 2 S max_i lambda_i e^(mu L/lambda_i)
   / min lambda_i, the least over all A, B.
2. **mu** maximises mu / gamma(mu), the factor by which the decay rate mu beats the
   coupling bound (esthm: mu (1 - sigma) > gamma). log mu - max_i (mu L/lambda_i + log
   lambda_i) is concave; its maximum lies in [min lambda_i, max lambda_i] / L. When the
   best ratio r* is <= 1, esthm #1 cannot hold for any design: this mu is then the closest
   (largest ratio) and the report says by how much S would have to shrink.
3. **sigma** takes half of the decay margin, sigma = (1 - 1/r*) / 2, so that the proven
   rate is mu (1 - sigma) - gamma = (mu - gamma) / 2; without a margin (r* <= 1) sigma =
   1/2: half of the nominal rate mu goes to the triggering threshold.
4. **B, varsigma_4** (select2, select4): B = max(2 sum A_i q_i^2, c Lambda-), so that B
   does not lower p_3, and varsigma_4 = (B - sum A_i q_i^2) / 2: half of select4's slack.
   select2 then reads varsigma_4 >= 4 zeta mu varsigma_4, i.e. zeta mu <= 1/4 (step 6).
5. **varsigma_1..n** (select3) = A_i e^(-mu L/lambda_i) / 2 = c lambda_i / 2: half of
   what select3 allows. Larger varsigma make m more negative (fewer events).
6. **zeta** (select1) = the largest with margin two: min_i varsigma_i / (2 max(B e^(mu
   L/Lambda-), mu) eps_i), and at most 1 / (8 mu) (select2 with margin two). tau* of
   Theorem minimalthm grows with zeta (varphi_1, varphi_2 fall), so zeta is as large as
   select1 and select2 allow.
7. **eta** = mu (1 - sigma): m forgets at the nominal rate of V; it exceeds mu (1 - sigma)
   - gamma, so esthm #2 holds.
8. **c**: the scale of V is free (every condition is homogeneous in A, B, varsigma); c
   puts the largest varsigma at 1/2, inside the (0, 1) of Theorem esthm.

m0 and the noise dead band are not part of the theorems and are passed through.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from arzsumo.control.design_check import boundary_eps, coupling_bound, inverse_p1
from arzsumo.control.etc import PAPER_DESIGN, EtcDesign
from arzsumo.control.kernels import Kernels
from arzsumo.model.characteristic import CharacteristicSystem

#: the margin on every inequality the design can satisfy (select1-select4)
MARGIN = 2.0


@dataclass(frozen=True)
class DesignChoice:
    """What :func:`design_for` chose and what it predicts.

    ``cannot_hold`` names the conditions no design can meet for this system as
    :meth:`DesignReport.failing` names them ("esthm #1"; empty when feasible), ``why``
    gives one sentence for each.
    """

    design: EtcDesign
    cannot_hold: tuple[str, ...]
    why: tuple[str, ...]
    ratio: float        # r* = mu / gamma at the chosen mu (> 1: esthm #1 holds)
    coupling: float     # S of gamma, 1/s

    @property
    def feasible(self) -> bool:
        """Whether every condition holds."""
        return not self.cannot_hold


def gamma_of_mu(system: CharacteristicSystem, coupling: float, mu: float) -> float:
    """The least gamma (1/s) over all A, B at this mu (module docstring, step 1)."""
    lam, length = system.lam_plus, system.length
    return float(2 * coupling * np.max(lam * np.exp(mu * length / lam)) / lam.min())


def best_mu(system: CharacteristicSystem, coupling: float) -> tuple[float, float]:
    """(mu, r*) maximising mu / gamma(mu) (step 2); mu in 1/s."""
    lam, length = system.lam_plus, system.length
    lo, hi = float(lam.min()) / length, float(lam.max()) / length

    def neg_log_ratio(mu: float) -> float:
        return -(math.log(mu) - math.log(gamma_of_mu(system, coupling, mu)))

    if hi - lo <= 1e-12 * hi:
        mu = lo
    else:
        mu = float(minimize_scalar(neg_log_ratio, bounds=(lo, hi), method="bounded",
                                   options={"xatol": 1e-9 * hi}).x)
    return mu, mu / gamma_of_mu(system, coupling, mu)


def _weights(system: CharacteristicSystem, mu: float) -> tuple[np.ndarray, float, float]:
    """A (c = 1), B and varsigma_4 for unit scale (steps 1 and 4)."""
    lam, q = system.lam_plus, system.Q
    A = lam * np.exp(mu * system.length / lam)
    aq = float(A @ q**2)
    B = max(MARGIN * aq, system.lam_minus)
    return A, B, (B - aq) / MARGIN


def _zeta(system: CharacteristicSystem, eps: np.ndarray, vs: np.ndarray, B: float,
          mu: float) -> float:
    """The largest zeta select1 and select2 allow, with margin two (step 6)."""
    b_exp = B * math.exp(mu * system.length / system.lam_minus)
    pos = eps > 0
    cap = 1.0 / (4 * MARGIN * mu)
    if not np.any(pos):
        return cap
    return min(cap, float(np.min(vs[pos] / (MARGIN * max(b_exp, mu) * eps[pos]))))


def design_for(system: CharacteristicSystem, kernels: Kernels,
               base: EtcDesign = PAPER_DESIGN) -> DesignChoice:
    """Choose mu, sigma, zeta, A, B, varsigma and eta for a system (module docstring).

    ``kernels`` are the system's backstepping kernels (the grid design_check will use);
    ``base`` supplies the fields the theorems do not fix (m0, the noise dead band). Only
    esthm #1 can be infeasible: every other condition is met by construction.
    """
    coupling = coupling_bound(system, kernels, inverse_p1(kernels))
    mu, ratio = best_mu(system, coupling)
    sigma = (1 - 1 / ratio) / 2 if ratio > 1 else 0.5
    A, B, vs4 = _weights(system, mu)
    vs = A * np.exp(-mu * system.length / system.lam_plus) / MARGIN
    scale = 0.5 / max(float(vs.max()), vs4)
    A, B, vs, vs4 = A * scale, B * scale, vs * scale, vs4 * scale
    zeta = _zeta(system, boundary_eps(system, kernels), vs, B, mu)
    design = base.with_(mu=mu, sigma=sigma, zeta=zeta, eta=mu * (1 - sigma), A=tuple(A),
                        B=B, varsigma=(*vs, vs4))
    if ratio > 1:
        return DesignChoice(design, (), (), ratio, coupling)
    why = (f"esthm #1: mu (1 - sigma) > gamma needs mu / gamma > 1, but gamma >= 2 S "
           f"max_i lambda_i e^(mu L/lambda_i) / min lambda_i for every A, B, and the best "
           f"mu = {mu:.3e} 1/s gives mu / gamma = {ratio:.3g}: the coupling S = "
           f"{coupling:.3e} 1/s would have to be {1 / ratio:.3g} times smaller",)
    return DesignChoice(design, ("esthm #1",), why, ratio, coupling)
