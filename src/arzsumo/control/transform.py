"""The backstepping transform (label back4), its inverse (label invback) and the control law.

All operators act on states given at the kernel grid nodes x_j = j h, with integrals by
the trapezoid rule, and on scaled Riemann variables w-bar of shape (n+1, n_cells+1).
"""

from __future__ import annotations

import numpy as np

from arzsumo.control.kernels import Kernels, trapezoid_weights
from arzsumo.model.characteristic import CharacteristicSystem


class BacksteppingTransform:
    """Forward map w-bar -> (alpha, beta) and inverse (alpha, beta) -> w-bar on a kernel grid.

    Forward (back4):  beta(x) = w-(x) - int_0^x K(x, xi) w+(xi) + M(x, xi) w-(xi) dxi.
    Inverse (invback): w-(x) = beta(x) + int_0^x L(x, xi) alpha(xi) + N(x, xi) beta(xi) dxi.
    Each is a lower-triangular matrix-vector product, O(n n_cells^2).
    """

    def __init__(self, kernels: Kernels) -> None:
        w = trapezoid_weights(kernels.n_cells, kernels.h)
        self._fk = w[None] * kernels.K            # (n, N+1, N+1)
        self._fm = w * kernels.M
        self._il = w[None] * kernels.L
        self._in = w * kernels.N

    def forward(self, w_bar: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(alpha, beta) of a state w-bar (n+1, N+1): alpha (n, N+1), beta (N+1,)."""
        w_plus, w_minus = w_bar[:-1], w_bar[-1]
        beta = w_minus - self._fm @ w_minus - np.einsum("ijl,il->j", self._fk, w_plus)
        return w_plus, beta

    def inverse(self, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
        """w-bar from (alpha, beta)."""
        w_minus = beta + self._in @ beta + np.einsum("ijl,il->j", self._il, alpha)
        return np.vstack([alpha, w_minus])


class BacksteppingLaw:
    """The continuous law control_law as precomputed gains: one evaluation is a dot product.

    U-bar(t) = int_0^L L(L, xi) alpha + N(L, xi) beta dxi - R w+(L, t)
             = int_0^L K(L, xi) w+ + M(L, xi) w- dxi - R w+(L, t),

    the second form because the inverse transform at x = L gives
    int (L alpha + N beta) = w-(L) - beta(L) = int (K w+ + M w-). Both are provided; the
    gains act on scaled Riemann variables at the kernel grid nodes.
    """

    def __init__(self, system: CharacteristicSystem, kernels: Kernels) -> None:
        n = system.n
        w = trapezoid_weights(kernels.n_cells, kernels.h)[-1]          # weights of int_0^L
        self.system = system
        self.gain = np.vstack([kernels.K[:, -1, :], kernels.M[None, -1, :]]) * w
        self.gain[:n, -1] -= system.R                                   # - R w+(L)
        self.target_gain = np.vstack([kernels.L[:, -1, :], kernels.N[None, -1, :]]) * w

    def u_bar(self, w_bar: np.ndarray) -> float:
        """U-bar from the plant state w-bar (n+1, N+1)."""
        return float(np.sum(self.gain * w_bar))

    def u_bar_from_target(self, alpha: np.ndarray, beta: np.ndarray) -> float:
        """U-bar from the target state (paper's form of control_law); w+(L) = alpha(L)."""
        n = self.system.n
        return float(np.sum(self.target_gain[:n] * alpha) + self.target_gain[n] @ beta
                     - self.system.R @ alpha[:, -1])

    def u_bar_no_kernel(self, w_bar: np.ndarray) -> float:
        """Only the reflection cancellation -R w+(L): the no-kernel comparison law."""
        return float(-self.system.R @ w_bar[: self.system.n, -1])
