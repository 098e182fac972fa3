"""Physical flux, wave-speed bounds, numerical fluxes and MUSCL reconstruction
(docs/twin.md, "Numerical flux").

A donor-cell flux from the left is not upwind in congestion (lambda_4 < 0), so both
fluxes upwind every family by the sign of its speed bounds: ``hll`` (default), with
S_L = min(lambda_min(q_L), lambda_min(q_R)) and S_R = max(lambda_max(q_L), lambda_max(q_R)),
is the donor cell from the left where S_L >= 0 and positivity-preserving for densities under
CFL <= 1; ``rusanov`` (alpha = max |lambda|) is more diffusive. The wave speeds are v_h, v_a
and the eigenvalues of J_ij = delta_ij v_i + rho_i dVe_i/drho_j at the actual state
(docs/characteristic_form.md, section 2). ``muscl`` reconstructs (rho_h, w_h, rho_a, w_a),
w_i = v_i - Ve_i(AO), with a slope limiter, so face densities stay between neighbouring
cell values. All functions are vectorised; arrays are shaped (4, n).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from arzsumo.model.fd import speed_terms_of_ao
from arzsumo.model.params import ModelParameters
from arzsumo.pde.state import RHO_A, RHO_H, Y_A, Y_H

Limiter = Callable[[np.ndarray, np.ndarray], np.ndarray]
NumericalFlux = Callable[["Waves", "Waves"], tuple[np.ndarray, np.ndarray]]


def physical_flux(q: np.ndarray, v_h: np.ndarray, v_a: np.ndarray) -> np.ndarray:
    """f(q) = (rho_h v_h, y_h v_h, rho_a v_a, y_a v_a), veh/s and veh/s^2 (section 2)."""
    f = np.empty_like(q)
    np.multiply(q[RHO_H], v_h, out=f[RHO_H])
    np.multiply(q[Y_H], v_h, out=f[Y_H])
    np.multiply(q[RHO_A], v_a, out=f[RHO_A])
    np.multiply(q[Y_A], v_a, out=f[Y_A])
    return f


class Waves(NamedTuple):
    """States with their physical flux and wave-speed bounds (all vectorised).

    q, f : (4, n) conserved variables and physical flux; v_h, v_a : (n,) speeds, m/s;
    lo, hi : (n,) smallest and largest characteristic speed, m/s.
    """

    q: np.ndarray
    f: np.ndarray
    v_h: np.ndarray
    v_a: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    def sel(self, idx: slice) -> Waves:
        """The same data restricted to the cells ``idx`` (the last axis)."""
        return Waves(*(a[..., idx] for a in self))


def state_speeds(p: ModelParameters, q: np.ndarray) -> tuple[np.ndarray, ...]:
    """(v_h, v_a, mu_low, mu_high) at conserved states ``q``, all m/s.

    mu_low <= mu_high are the eigenvalues of the density Jacobian J with the actual
    speeds; with v_h, v_a they are the four characteristic speeds of the nonlinear system
    (lambda_4 = mu_low, lambda_2 = mu_high at an equilibrium).
    """
    rho_h, rho_a = q[RHO_H], q[RHO_A]
    ao = (p.area_h * rho_h + p.area_a * rho_a) / p.road_width
    ve_h, ve_a, d_h, d_a = speed_terms_of_ao(p, ao)
    v_h = q[Y_H] / rho_h + ve_h
    v_a = q[Y_A] / rho_a + ve_a
    ah, aa = p.area_h / p.road_width, p.area_a / p.road_width
    j11 = v_h + rho_h * d_h * ah
    j22 = v_a + rho_a * d_a * aa
    j12j21 = (rho_h * d_h) * (rho_a * d_a) * (aa * ah)        # >= 0: real eigenvalues
    mean = 0.5 * (j11 + j22)
    disc = np.sqrt(np.maximum(0.25 * (j11 - j22) ** 2 + j12j21, 0.0))
    return v_h, v_a, mean - disc, mean + disc


def waves(p: ModelParameters, q: np.ndarray) -> Waves:
    """Physical flux and speed bounds of states ``q`` (4, n), computed once per step."""
    v_h, v_a, lo, hi = state_speeds(p, q)
    return Waves(q, physical_flux(q, v_h, v_a), v_h, v_a,
                 np.minimum(lo, np.minimum(v_h, v_a)), np.maximum(hi, np.maximum(v_h, v_a)))


def hll(left: Waves, right: Waves) -> tuple[np.ndarray, np.ndarray]:
    """HLL flux (4, n_faces) between ``left`` and ``right`` states, and the largest wave
    speed magnitude at each face (n_faces,), m/s, for the CFL condition."""
    s_l = np.minimum(left.lo, right.lo)
    s_r = np.maximum(left.hi, right.hi)
    sl0 = np.minimum(s_l, 0.0)
    sr0 = np.maximum(s_r, 0.0)
    width = sr0 - sl0
    width = np.where(width > 0.0, width, 1.0)
    # clamping the speeds to 0 reproduces the three HLL cases in one formula
    flux = (sr0 * left.f - sl0 * right.f + sl0 * sr0 * (right.q - left.q)) / width
    return flux, np.maximum(-s_l, s_r)


def rusanov(left: Waves, right: Waves) -> tuple[np.ndarray, np.ndarray]:
    """Rusanov (local Lax-Friedrichs) flux, alpha = max |lambda| of both states."""
    alpha = np.maximum(np.maximum(-left.lo, left.hi), np.maximum(-right.lo, right.hi))
    return 0.5 * (left.f + right.f) - 0.5 * alpha * (right.q - left.q), alpha


#: Numerical fluxes, all with the signature ``(left: Waves, right: Waves) -> (flux, s_max)``.
FLUXES: dict[str, NumericalFlux] = {"hll": hll, "rusanov": rusanov}


# --- limiters: phi(a, b) with a, b the backward and forward differences -----------------

def minmod(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Minmod slope: the smaller difference when both have the same sign, else 0."""
    return np.where(a * b > 0.0, np.sign(a) * np.minimum(np.abs(a), np.abs(b)), 0.0)


def van_leer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Van Leer (harmonic mean) slope."""
    ab = a * b
    den = np.where(ab > 0.0, a + b, 1.0)
    return np.where(ab > 0.0, 2.0 * ab / den, 0.0)


def monotonized_central(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """MC slope: minmod(2a, (a+b)/2, 2b)."""
    c = 0.5 * (a + b)
    m = np.minimum(np.minimum(2.0 * np.abs(a), 2.0 * np.abs(b)), np.abs(c))
    return np.where(a * b > 0.0, np.sign(c) * m, 0.0)


LIMITERS: dict[str, Limiter] = {"minmod": minmod, "vanleer": van_leer,
                                "mc": monotonized_central}


def from_reconstruction(r: np.ndarray) -> np.ndarray:
    """Conserved variables from (rho_h, w_h, rho_a, w_a)."""
    q = r.copy()
    q[Y_H] *= r[RHO_H]
    q[Y_A] *= r[RHO_A]
    return q


def muscl_faces(r_padded: np.ndarray, limiter: Limiter) -> tuple[np.ndarray, np.ndarray]:
    """Values (4, n) at the east and west face of each cell, limited by one of
    :data:`LIMITERS`, from reconstruction variables (4, n + 2) with one ghost at each end."""
    d = np.diff(r_padded, axis=1)                  # (4, n + 1)
    slope = limiter(d[:, :-1], d[:, 1:])           # (4, n), per cell width
    centre = r_padded[:, 1:-1]
    return centre + 0.5 * slope, centre - 0.5 * slope
