"""Relaxation source, integrated exactly (paper, section 2, right-hand sides).

In conservative variables the source is (0, -y_h / tau_h, 0, -y_a / tau_a): densities are
untouched and each y_i decays linearly, because rho_i (Ve_i(AO) - v_i) / tau_i = -y_i / tau_i
and rho_i (hence AO, hence Ve_i) does not change during the source step. The source ODE
is therefore solved exactly by y_i(t + dt) = exp(-dt / tau_i) y_i(t), which is
unconditionally stable however small tau_i and large dt are. The twin applies it by
Strang splitting: half a source step, a transport step, half a source step.
"""

from __future__ import annotations

import math

import numpy as np

from arzsumo.model.params import ModelParameters
from arzsumo.pde.state import Y_A, Y_H


def relax(p: ModelParameters, q: np.ndarray, dt: float) -> np.ndarray:
    """Exact solution of q_t = S(q) over ``dt`` seconds; returns a new array.

    Parameters
    ----------
    p : ModelParameters
        Supplies tau_h and tau_a (s).
    q : ndarray, shape (4, n)
        Conserved variables (rho_h, y_h, rho_a, y_a).
    dt : float
        Duration in s, >= 0.
    """
    out = q.copy()
    out[Y_H] *= math.exp(-dt / p.tau_h)
    out[Y_A] *= math.exp(-dt / p.tau_a)
    return out
